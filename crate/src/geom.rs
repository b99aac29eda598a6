//! Small 3D vector and quaternion maths in `f64`.
//!
//! Conventions follow HumanML3D so that features computed here match its files: quaternions are
//! stored `(w, x, y, z)`, act on column vectors, and compose as `a * b` = "apply `b`, then `a`".
//! The world is Y up, metres.

/// A point or direction in metres (x, y, z), Y up.
pub type Vec3 = [f64; 3];

/// `a + b`.
pub fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a - b`.
pub fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a * s`.
pub fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Linear interpolation `a + (b - a) * t`.
pub fn lerp(a: Vec3, b: Vec3, t: f64) -> Vec3 {
    add(a, scale(sub(b, a), t))
}

/// Dot product.
pub fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cross product `a × b` (right-handed).
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Euclidean length.
pub fn norm(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}

/// `a / |a|`; a zero vector stays zero rather than becoming NaN.
pub fn normalize(a: Vec3) -> Vec3 {
    let n = norm(a);
    if n > 0.0 {
        scale(a, 1.0 / n)
    } else {
        a
    }
}

/// Distance between two points.
pub fn dist(a: Vec3, b: Vec3) -> f64 {
    norm(sub(a, b))
}

/// Smoothstep easing of `u` in 0–1 (clamped): starts and ends with zero speed.
pub fn ease(u: f64) -> f64 {
    let u = u.clamp(0.0, 1.0);
    u * u * (3.0 - 2.0 * u)
}

/// A rotation as a unit quaternion `(w, x, y, z)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quat(pub [f64; 4]);

impl Quat {
    /// The identity rotation.
    pub const IDENTITY: Quat = Quat([1.0, 0.0, 0.0, 0.0]);

    /// Rotation of `angle` radians about the unit `axis` (right-hand rule).
    pub fn from_axis_angle(axis: Vec3, angle: f64) -> Quat {
        let (s, c) = (angle * 0.5).sin_cos();
        let a = normalize(axis);
        Quat([c, a[0] * s, a[1] * s, a[2] * s])
    }

    /// Rotation about +Y by `angle` radians (a turn on the ground plane).
    pub fn from_yaw(angle: f64) -> Quat {
        Quat::from_axis_angle([0.0, 1.0, 0.0], angle)
    }

    /// Hamilton product: the rotation that applies `rhs` first, then `self`.
    // A named method rather than `*`: the order matters and reads better spelled out.
    #[allow(clippy::should_implement_trait)]
    pub fn mul(self, rhs: Quat) -> Quat {
        let [aw, ax, ay, az] = self.0;
        let [bw, bx, by, bz] = rhs.0;
        Quat([
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ])
    }

    /// The conjugate, which is the inverse for a unit quaternion.
    pub fn inv(self) -> Quat {
        let [w, x, y, z] = self.0;
        Quat([w, -x, -y, -z])
    }

    /// Scaled to unit length.
    pub fn normalized(self) -> Quat {
        let n = self.0.iter().map(|v| v * v).sum::<f64>().sqrt();
        if n > 0.0 {
            Quat(self.0.map(|v| v / n))
        } else {
            Quat::IDENTITY
        }
    }

    /// Rotates the vector `v`.
    pub fn rotate(self, v: Vec3) -> Vec3 {
        let [w, x, y, z] = self.0;
        let q = [x, y, z];
        let uv = cross(q, v);
        let uuv = cross(q, uv);
        add(v, scale(add(scale(uv, w), uuv), 2.0))
    }

    /// The shortest rotation that turns direction `from` into direction `to` (neither needs
    /// to be unit length). Matches HumanML3D's `qbetween`, including its behaviour for
    /// opposite vectors (a degenerate, normalised result), so features stay comparable.
    pub fn between(from: Vec3, to: Vec3) -> Quat {
        let v = cross(from, to);
        let w = (dot(from, from) * dot(to, to)).sqrt() + dot(from, to);
        Quat([w, v[0], v[1], v[2]]).normalized()
    }

    /// Spherical interpolation from `self` (t = 0) to `other` (t = 1) along the shorter arc.
    pub fn slerp(self, other: Quat, t: f64) -> Quat {
        let mut b = other.0;
        let mut cos: f64 = self.0.iter().zip(&b).map(|(x, y)| x * y).sum();
        // q and −q are the same rotation; the shorter arc avoids a needless full turn.
        if cos < 0.0 {
            b = b.map(|v| -v);
            cos = -cos;
        }
        let (wa, wb) = if cos > 0.9995 {
            (1.0 - t, t)
        } else {
            let theta = cos.min(1.0).acos();
            let sin = theta.sin();
            (((1.0 - t) * theta).sin() / sin, (t * theta).sin() / sin)
        };
        Quat(std::array::from_fn(|i| wa * self.0[i] + wb * b[i])).normalized()
    }

    /// The 3×3 rotation matrix, row-major: `m[row][col]`.
    pub fn to_matrix(self) -> [[f64; 3]; 3] {
        let [r, i, j, k] = self.0;
        let two_s = 2.0 / (r * r + i * i + j * j + k * k);
        [
            [
                1.0 - two_s * (j * j + k * k),
                two_s * (i * j - k * r),
                two_s * (i * k + j * r),
            ],
            [
                two_s * (i * j + k * r),
                1.0 - two_s * (i * i + k * k),
                two_s * (j * k - i * r),
            ],
            [
                two_s * (i * k - j * r),
                two_s * (j * k + i * r),
                1.0 - two_s * (i * i + j * j),
            ],
        ]
    }

    /// The quaternion of a proper rotation matrix (row-major), with `w ≥ 0`.
    pub fn from_matrix(m: [[f64; 3]; 3]) -> Quat {
        let trace = m[0][0] + m[1][1] + m[2][2];
        let q = if trace > 0.0 {
            let s = (trace + 1.0).sqrt() * 2.0;
            [
                0.25 * s,
                (m[2][1] - m[1][2]) / s,
                (m[0][2] - m[2][0]) / s,
                (m[1][0] - m[0][1]) / s,
            ]
        } else if m[0][0] > m[1][1] && m[0][0] > m[2][2] {
            let s = (1.0 + m[0][0] - m[1][1] - m[2][2]).sqrt() * 2.0;
            [
                (m[2][1] - m[1][2]) / s,
                0.25 * s,
                (m[0][1] + m[1][0]) / s,
                (m[0][2] + m[2][0]) / s,
            ]
        } else if m[1][1] > m[2][2] {
            let s = (1.0 + m[1][1] - m[0][0] - m[2][2]).sqrt() * 2.0;
            [
                (m[0][2] - m[2][0]) / s,
                (m[0][1] + m[1][0]) / s,
                0.25 * s,
                (m[1][2] + m[2][1]) / s,
            ]
        } else {
            let s = (1.0 + m[2][2] - m[0][0] - m[1][1]).sqrt() * 2.0;
            [
                (m[1][0] - m[0][1]) / s,
                (m[0][2] + m[2][0]) / s,
                (m[1][2] + m[2][1]) / s,
                0.25 * s,
            ]
        };
        let q = Quat(q).normalized();
        if q.0[0] < 0.0 {
            Quat(q.0.map(|v| -v))
        } else {
            q
        }
    }

    /// The rotation whose matrix has the orthonormal columns `x`, `y`, `z`, i.e. the rotation
    /// that carries the world axes onto that frame.
    pub fn from_columns(x: Vec3, y: Vec3, z: Vec3) -> Quat {
        Quat::from_matrix([[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]])
    }
}

/// Gaussian smoothing along a sequence, as `scipy.ndimage.gaussian_filter1d(x, sigma,
/// mode='nearest')` with the default truncation at 4 σ: edges repeat the first/last sample.
pub fn gaussian_smooth(values: &[Vec3], sigma: f64) -> Vec<Vec3> {
    let radius = (4.0 * sigma + 0.5) as i64;
    let mut weights: Vec<f64> = (-radius..=radius)
        .map(|x| (-0.5 * (x * x) as f64 / (sigma * sigma)).exp())
        .collect();
    let total: f64 = weights.iter().sum();
    weights.iter_mut().for_each(|w| *w /= total);
    let last = values.len() as i64 - 1;
    (0..values.len() as i64)
        .map(|i| {
            let mut acc = [0.0; 3];
            for (k, w) in weights.iter().enumerate() {
                let j = (i + k as i64 - radius).clamp(0, last) as usize;
                acc = add(acc, scale(values[j], *w));
            }
            acc
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3) -> bool {
        dist(a, b) < 1e-12
    }

    #[test]
    fn between_maps_from_onto_to() {
        let q = Quat::between([1.0, 0.0, 0.0], [0.0, 0.0, 2.0]);
        assert!(close(q.rotate([1.0, 0.0, 0.0]), [0.0, 0.0, 1.0]));
    }

    #[test]
    fn matrix_round_trip() {
        let q = Quat::from_axis_angle([0.3, -1.0, 0.5], 2.5);
        let back = Quat::from_matrix(q.to_matrix());
        let v = [0.2, -0.7, 1.3];
        assert!(close(q.rotate(v), back.rotate(v)));
    }

    #[test]
    fn composition_applies_right_first() {
        let a = Quat::from_yaw(0.4);
        let b = Quat::from_axis_angle([1.0, 0.0, 0.0], 1.1);
        let v = [0.1, 0.2, 0.3];
        assert!(close(a.mul(b).rotate(v), a.rotate(b.rotate(v))));
        assert!(close(a.mul(a.inv()).rotate(v), v));
    }

    #[test]
    fn gaussian_of_constant_is_constant() {
        let xs = vec![[1.0, 2.0, 3.0]; 7];
        for y in gaussian_smooth(&xs, 20.0) {
            assert!(close(y, [1.0, 2.0, 3.0]));
        }
    }
}
