//! Checks that a walked path has the requested shape, on the root path rebuilt from features
//! (see [`root_path`](super::root::root_path)).

use serde::Serialize;

/// Steps shorter than this (metres) say nothing reliable about direction: standing still, or
/// the noise of a pelvis that sways on the spot.
const MIN_STEP_M: f64 = 1e-3;

/// How well a ground path (x, z in metres, Y up) matches a circle.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct CircleReport {
    /// Distance from the last point back to the first, metres.
    pub closure_error_m: f64,
    /// Centre (x, z) of the least-squares circle through the points, metres.
    pub centre_m: [f64; 2],
    /// Radius of that circle, metres.
    pub radius_m: f64,
    /// Mean of |distance to the centre − radius| over the points, metres.
    pub mean_radius_error_m: f64,
    /// Largest such error, metres.
    pub max_radius_error_m: f64,
    /// Whether the net turn is clockwise seen from above (to the walker's right, from +Z
    /// towards −X).
    pub turned_clockwise: bool,
    /// Size of the net turn of the walking direction, degrees (about 360 for one circle);
    /// its direction is [`CircleReport::turned_clockwise`].
    pub total_turn_deg: f64,
    /// Whether the turn direction is the one requested.
    pub matches_direction: bool,
}

/// Measures `path_xz` against a circle walked clockwise (`clockwise`) or counter-clockwise,
/// both seen from above. The circle is the algebraic least-squares fit (Kåsa) through the
/// points. With fewer than three points, or all points on a line, the radius and its errors
/// are NaN.
pub fn circle_report(path_xz: &[[f64; 2]], clockwise: bool) -> CircleReport {
    let closure_error_m = match (path_xz.first(), path_xz.last()) {
        (Some(a), Some(b)) => (a[0] - b[0]).hypot(a[1] - b[1]),
        _ => 0.0,
    };
    let (centre_m, radius_m) = fit_circle(path_xz).unwrap_or(([f64::NAN; 2], f64::NAN));
    let errors: Vec<f64> = path_xz
        .iter()
        .map(|p| ((p[0] - centre_m[0]).hypot(p[1] - centre_m[1]) - radius_m).abs())
        .collect();
    let mean_radius_error_m = if errors.is_empty() {
        f64::NAN
    } else {
        errors.iter().sum::<f64>() / errors.len() as f64
    };
    let max_radius_error_m = errors.iter().copied().fold(f64::NAN, f64::max);
    let turn = net_turn(path_xz);
    let turned_clockwise = turn < 0.0;
    CircleReport {
        closure_error_m,
        centre_m,
        radius_m,
        mean_radius_error_m,
        max_radius_error_m,
        turned_clockwise,
        total_turn_deg: turn.abs().to_degrees(),
        matches_direction: turned_clockwise == clockwise,
    }
}

/// Net change of walking direction along the path, radians; positive is counter-clockwise
/// seen from above (to the left), the sense of [`heading_of`](super::path::heading_of).
pub fn net_turn(path_xz: &[[f64; 2]]) -> f64 {
    let mut previous: Option<f64> = None;
    let mut total = 0.0;
    for w in path_xz.windows(2) {
        let d = [w[1][0] - w[0][0], w[1][1] - w[0][1]];
        if d[0].hypot(d[1]) < MIN_STEP_M {
            continue;
        }
        let h = super::path::heading_of(d);
        if let Some(p) = previous {
            let tau = std::f64::consts::TAU;
            let mut delta = (h - p) % tau;
            if delta > std::f64::consts::PI {
                delta -= tau;
            } else if delta < -std::f64::consts::PI {
                delta += tau;
            }
            total += delta;
        }
        previous = Some(h);
    }
    total
}

/// Centre and radius minimising Σ(x² + z² + Dx + Ez + F)², on coordinates centred on their
/// mean for conditioning.
fn fit_circle(points: &[[f64; 2]]) -> Option<([f64; 2], f64)> {
    if points.len() < 3 {
        return None;
    }
    let n = points.len() as f64;
    let mean = [
        points.iter().map(|p| p[0]).sum::<f64>() / n,
        points.iter().map(|p| p[1]).sum::<f64>() / n,
    ];
    let mut m = [[0.0f64; 3]; 3];
    let mut rhs = [0.0f64; 3];
    for p in points {
        let (x, z) = (p[0] - mean[0], p[1] - mean[1]);
        let row = [x, z, 1.0];
        let r2 = x * x + z * z;
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += row[i] * row[j];
            }
            rhs[i] -= row[i] * r2;
        }
    }
    let [d, e, f] = solve3(m, rhs)?;
    let (cx, cz) = (-d / 2.0, -e / 2.0);
    let r2 = cx * cx + cz * cz - f;
    if !(r2 > 0.0 && r2.is_finite()) {
        return None;
    }
    Some(([cx + mean[0], cz + mean[1]], r2.sqrt()))
}

/// Solves `m · x = b` by Gaussian elimination with partial pivoting; `None` if singular.
fn solve3(mut m: [[f64; 3]; 3], mut b: [f64; 3]) -> Option<[f64; 3]> {
    let scale = m.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
    for col in 0..3 {
        let pivot = (col..3).max_by(|&i, &j| m[i][col].abs().total_cmp(&m[j][col].abs()))?;
        if m[pivot][col].abs() <= 1e-12 * scale {
            return None;
        }
        m.swap(col, pivot);
        b.swap(col, pivot);
        let pivot_row = m[col];
        for row in col + 1..3 {
            let k = m[row][col] / pivot_row[col];
            for (dst, src) in m[row].iter_mut().zip(pivot_row).skip(col) {
                *dst -= k * src;
            }
            b[row] -= k * b[col];
        }
    }
    let mut x = [0.0; 3];
    for row in (0..3).rev() {
        let s: f64 = (row + 1..3).map(|c| m[row][c] * x[c]).sum();
        x[row] = (b[row] - s) / m[row][row];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::features_to_joints;
    use crate::trajectory::root::{map_curve, root_path, MapOptions};
    use crate::trajectory::shapes::{Shape, Side};
    use crate::trajectory::test_motion::{walk, walking_poses};

    #[test]
    fn exact_circles_are_measured_exactly() {
        let r = 2.0;
        let cw: Vec<[f64; 2]> = (0..=100)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / 100.0;
                [a.cos() * r - r, a.sin() * r]
            })
            .collect();
        // x = r cos a − r, z = r sin a: from the origin heading +Z towards −X, clockwise.
        let rep = circle_report(&cw, true);
        assert!(rep.closure_error_m < 1e-12);
        assert!((rep.radius_m - r).abs() < 1e-9);
        assert!((rep.centre_m[0] + r).abs() < 1e-9 && rep.centre_m[1].abs() < 1e-9);
        assert!(rep.mean_radius_error_m < 1e-9);
        assert!(rep.turned_clockwise && rep.matches_direction);
        assert!((rep.total_turn_deg - 360.0).abs() < 4.0, "{rep:?}");
        let mirrored: Vec<[f64; 2]> = cw.iter().map(|p| [-p[0], p[1]]).collect();
        let rep = circle_report(&mirrored, true);
        assert!(!rep.turned_clockwise && !rep.matches_direction);
    }

    #[test]
    fn degenerate_inputs_do_not_panic() {
        let rep = circle_report(&[], false);
        assert!(rep.radius_m.is_nan());
        let line: Vec<[f64; 2]> = (0..10).map(|i| [0.0, i as f64]).collect();
        let rep = circle_report(&line, false);
        assert!(rep.radius_m.is_nan() && rep.total_turn_deg.abs() < 1e-9);
    }

    /// The end-to-end check: a straight synthetic walk made to walk "in a circle clockwise"
    /// turns clockwise, closes within a few centimetres and stays on its circle.
    #[test]
    fn a_straight_walk_mapped_onto_a_clockwise_circle_walks_it() {
        for f in [
            walk(161, 1.2, 0.0),
            // Features computed from joints (a real feature pipeline), 7 s at 1.1 m/s.
            crate::features::joints_to_features(
                &walking_poses(141, 1.1 / 20.0, 0.0),
                &crate::skeleton::Offsets::from_pose(&walking_poses(1, 0.0, 0.0)[0]),
            )
            .unwrap()
            .0,
        ] {
            let (mapped, _) = map_curve(
                &f,
                &Shape::Circle(Side::Right).curve(),
                &MapOptions::default(),
            )
            .unwrap();
            let path = root_path(&mapped);
            assert_eq!(path.len(), features_to_joints(&mapped).len());
            let rep = circle_report(&path, true);
            assert!(rep.turned_clockwise && rep.matches_direction, "{rep:?}");
            assert!(rep.closure_error_m < 0.03, "{rep:?}");
            assert!(rep.mean_radius_error_m < 0.02, "{rep:?}");
            assert!((rep.total_turn_deg - 360.0).abs() < 10.0, "{rep:?}");
            // The centre is on the walker's right at the start (−X).
            assert!(
                rep.centre_m[0] < 0.0 && rep.centre_m[1].abs() < 0.05,
                "{rep:?}"
            );
        }
    }
}
