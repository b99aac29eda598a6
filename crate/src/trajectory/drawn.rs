//! Paths drawn with the pointer on the page's ground plane, as data: the checks a drawn
//! point list must pass before it becomes a [`Trajectory::Points`](super::Trajectory::Points)
//! (a plan and a share link carry it, so a doctored one must fail with a clear message, never
//! cost much), and the thinning the page applies to a stroke before it sends it.
//!
//! Points are `[x, z]` on the ground in metres, in the motion's world frame: Y up, the motion
//! starts at the origin facing +Z, +X is the walker's left at the start.

/// Most points a drawn path may have. A stroke is thinned to this by [`thin`]; the spline
/// through them ([`ArcPath::from_points`](super::ArcPath::from_points)) needs no more to
/// follow a hand-drawn line.
pub const MAX_DRAWN_POINTS: usize = 512;
/// Largest coordinate of a drawn point, metres from the origin along either axis: far beyond
/// what a view of a walk shows, so only a doctored path reaches it.
pub const MAX_DRAWN_COORD_M: f64 = 100.0;
/// Shortest drawn path, metres: a shorter stroke is a click or a slip, not a path.
pub const MIN_DRAWN_LENGTH_M: f64 = 0.3;
/// Spacing below which [`thin`] drops a point, metres: finer than a hand draws on the ground.
pub const MIN_DRAWN_STEP_M: f64 = 0.02;

/// Why drawn points are not a path.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DrawnError {
    /// Fewer than two points.
    #[error(
        "a drawn path needs at least 2 points, got {0}: press on the ground, drag, then release"
    )]
    TooFewPoints(usize),
    /// More than [`MAX_DRAWN_POINTS`].
    #[error("a drawn path has at most {MAX_DRAWN_POINTS} points, this one {0}")]
    TooManyPoints(usize),
    /// A coordinate is NaN or infinite.
    #[error("point {index} of the drawn path is not a finite number")]
    NonFinite {
        /// Index of the point.
        index: usize,
    },
    /// A coordinate beyond ±[`MAX_DRAWN_COORD_M`].
    #[error(
        "point {index} of the drawn path is {value} m from the start along an axis, beyond \
         ±{MAX_DRAWN_COORD_M} m"
    )]
    OutOfRange {
        /// Index of the point.
        index: usize,
        /// The coordinate, metres.
        value: f64,
    },
    /// Shorter than [`MIN_DRAWN_LENGTH_M`].
    #[error(
        "the drawn path is {length_m:.2} m long, too short to walk: draw at least \
         {MIN_DRAWN_LENGTH_M} m on the ground"
    )]
    TooShort {
        /// Length of the polyline, metres.
        length_m: f64,
    },
}

/// Length of the polyline through `points`, metres.
pub fn polyline_length(points: &[[f64; 2]]) -> f64 {
    points
        .windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
        .sum()
}

/// Checks drawn points as data: 2 to [`MAX_DRAWN_POINTS`] points, every coordinate finite
/// and within ±[`MAX_DRAWN_COORD_M`] m, at least [`MIN_DRAWN_LENGTH_M`] long. Returns the
/// polyline's length in metres.
pub fn check_drawn(points: &[[f64; 2]]) -> Result<f64, DrawnError> {
    if points.len() < 2 {
        return Err(DrawnError::TooFewPoints(points.len()));
    }
    if points.len() > MAX_DRAWN_POINTS {
        return Err(DrawnError::TooManyPoints(points.len()));
    }
    for (index, p) in points.iter().enumerate() {
        if !p.iter().all(|v| v.is_finite()) {
            return Err(DrawnError::NonFinite { index });
        }
        if let Some(&value) = p.iter().find(|v| v.abs() > MAX_DRAWN_COORD_M) {
            return Err(DrawnError::OutOfRange { index, value });
        }
    }
    let length_m = polyline_length(points);
    if length_m < MIN_DRAWN_LENGTH_M {
        return Err(DrawnError::TooShort { length_m });
    }
    Ok(length_m)
}

/// A stroke as a drawn path keeps it: non-finite points dropped, each point rounded to the
/// millimetre (a share link stays short, and its JSON reads back to exactly these numbers),
/// points closer than `min_step_m` to the last kept one dropped (the stroke's last point is
/// always kept), then, if more than `max_points` remain, `max_points` of them picked evenly
/// by index, first and last included. The result may still fail [`check_drawn`] (too short,
/// out of range): that is for the caller to say.
pub fn thin(stroke: &[[f64; 2]], min_step_m: f64, max_points: usize) -> Vec<[f64; 2]> {
    let mm = |v: f64| (v * 1000.0).round() / 1000.0;
    let finite: Vec<[f64; 2]> = stroke
        .iter()
        .filter(|p| p.iter().all(|v| v.is_finite()))
        .map(|p| [mm(p[0]), mm(p[1])])
        .collect();
    let mut kept: Vec<[f64; 2]> = Vec::with_capacity(finite.len());
    for (i, p) in finite.iter().enumerate() {
        let last = i + 1 == finite.len();
        match kept.last() {
            Some(q) if (p[0] - q[0]).hypot(p[1] - q[1]) < min_step_m => {
                // The end of the stroke is where the user let go: it replaces the point
                // just before it rather than being lost (unless both coincide).
                if last && kept.len() > 1 && p != q {
                    *kept.last_mut().expect("kept is not empty") = *p;
                }
            }
            _ => kept.push(*p),
        }
    }
    let max_points = max_points.max(2);
    if kept.len() <= max_points {
        return kept;
    }
    let n = kept.len();
    (0..max_points)
        .map(|k| kept[(k * (n - 1) + (max_points - 1) / 2) / (max_points - 1)])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checks_name_what_is_wrong() {
        assert_eq!(check_drawn(&[[0.0, 0.0]]), Err(DrawnError::TooFewPoints(1)));
        assert_eq!(check_drawn(&[]), Err(DrawnError::TooFewPoints(0)));
        let many: Vec<[f64; 2]> = (0..=MAX_DRAWN_POINTS)
            .map(|i| [0.0, i as f64 * 0.01])
            .collect();
        assert_eq!(
            check_drawn(&many),
            Err(DrawnError::TooManyPoints(MAX_DRAWN_POINTS + 1))
        );
        assert!(check_drawn(&many[..MAX_DRAWN_POINTS]).is_ok());
        assert_eq!(
            check_drawn(&[[0.0, 0.0], [f64::NAN, 1.0]]),
            Err(DrawnError::NonFinite { index: 1 })
        );
        assert_eq!(
            check_drawn(&[[0.0, 0.0], [0.0, f64::INFINITY]]),
            Err(DrawnError::NonFinite { index: 1 })
        );
        assert_eq!(
            check_drawn(&[[0.0, 0.0], [0.0, 1.0], [-250.0, 1.0]]),
            Err(DrawnError::OutOfRange {
                index: 2,
                value: -250.0
            })
        );
        let short = check_drawn(&[[1.0, 1.0], [1.1, 1.1]]).unwrap_err();
        assert!(
            matches!(short, DrawnError::TooShort { length_m } if (length_m - 0.1414).abs() < 1e-3)
        );
        assert!(
            short.to_string().contains("0.14 m long, too short"),
            "{short}"
        );
        let length = check_drawn(&[[0.0, 0.0], [0.0, 3.0], [4.0, 3.0]]).unwrap();
        assert!((length - 7.0).abs() < 1e-12);
    }

    #[test]
    fn thinning_drops_close_points_and_keeps_the_ends() {
        // A stroke sampled every 5 mm along 1 m, with a NaN from a missed pick.
        let mut stroke: Vec<[f64; 2]> = (0..=200).map(|i| [0.0, i as f64 * 0.005]).collect();
        stroke.insert(50, [f64::NAN, 0.0]);
        let thinned = thin(&stroke, MIN_DRAWN_STEP_M, MAX_DRAWN_POINTS);
        assert_eq!(thinned.first(), Some(&[0.0, 0.0]));
        assert_eq!(thinned.last(), Some(&[0.0, 1.0]));
        assert!(thinned
            .windows(2)
            .all(|w| (w[1][1] - w[0][1]) >= MIN_DRAWN_STEP_M - 1e-9));
        // Every 4th or 5th sample, as float spacing falls either side of 2 cm.
        assert!((41..=51).contains(&thinned.len()), "{}", thinned.len());
        // Too many points for the cap: picked evenly, the ends kept.
        let long: Vec<[f64; 2]> = (0..2000).map(|i| [i as f64 * 0.03, 0.0]).collect();
        let capped = thin(&long, MIN_DRAWN_STEP_M, 100);
        assert_eq!(capped.len(), 100);
        assert_eq!(capped[0], long[0]);
        assert_eq!(capped[99], long[1999]);
        assert!(check_drawn(&capped).is_ok());
        // Rounded to the millimetre, and the JSON reads back to the same numbers.
        let rounded = thin(&[[0.12345, -1.00049], [2.0000001, 3.0]], 0.0, 10);
        assert_eq!(rounded, vec![[0.123, -1.0], [2.0, 3.0]]);
        let json = serde_json::to_string(&rounded).unwrap();
        assert_eq!(
            serde_json::from_str::<Vec<[f64; 2]>>(&json).unwrap(),
            rounded
        );
        // A click: one point, which the check then refuses.
        let click = thin(&[[1.0, 1.0], [1.001, 1.0], [1.0, 1.002]], 0.02, 10);
        assert_eq!(click.len(), 1);
        assert_eq!(check_drawn(&click), Err(DrawnError::TooFewPoints(1)));
    }
}
