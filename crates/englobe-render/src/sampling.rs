//! Random directions for the path tracer: an orthonormal frame around a normal and
//! cosine-weighted directions over the hemisphere (Malley's method: uniform points on the disk,
//! projected up; Pharr, Jakob and Humphreys, "Physically Based Rendering", section 13.6.3).

use englobe::Vec3;

/// Two unit vectors that make a right-handed orthonormal frame with the unit vector `n`
/// (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
pub fn orthonormal_frame(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3::new(b, sign + n.y * n.y * a, -n.y))
}

/// A direction around the unit normal `n` with density `cos θ / π`, from two uniform numbers in
/// `[0, 1)`.
pub fn cosine_hemisphere(n: Vec3, u1: f32, u2: f32) -> Vec3 {
    let r = u1.sqrt();
    let phi = 2.0 * std::f32::consts::PI * u2;
    let (x, y) = (r * phi.cos(), r * phi.sin());
    let z = (1.0 - u1).max(0.0).sqrt();
    let (t, b) = orthonormal_frame(n);
    t * x + b * y + n * z
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal() {
        for n in [Vec3::Z, -Vec3::Z, Vec3::X, Vec3::new(0.3, -0.5, 0.8).normalize(), Vec3::new(0.0, 0.0, -1.0)] {
            let (t, b) = orthonormal_frame(n);
            for (u, v) in [(t, b), (t, n), (b, n)] {
                assert!(u.dot(v).abs() < 1e-6);
            }
            assert!((t.length() - 1.0).abs() < 1e-6 && (b.length() - 1.0).abs() < 1e-6);
            assert!((t.cross(b) - n).length() < 1e-6, "right-handed");
        }
    }

    #[test]
    fn cosine_directions_lie_above_and_average_to_two_thirds() {
        // The mean of cos θ under the density cos θ / π is 2/3.
        let n = Vec3::new(0.2, 0.9, -0.3).normalize();
        let k = 64;
        let mut sum = 0.0;
        for i in 0..k {
            for j in 0..k {
                let d = cosine_hemisphere(n, (i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32);
                assert!((d.length() - 1.0).abs() < 1e-5);
                assert!(d.dot(n) >= 0.0);
                sum += d.dot(n);
            }
        }
        assert!((sum / (k * k) as f32 - 2.0 / 3.0).abs() < 1e-3);
    }
}
