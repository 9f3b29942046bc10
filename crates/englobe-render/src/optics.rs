//! The optics of the Whitted integrator: mirror reflection, Snell's law with total internal
//! reflection, the Fresnel equations for dielectrics, and the offset that starts secondary rays
//! just off a surface.

use englobe::Vec3;

/// The mirror direction of `d` about the normal `n` (unit).
#[inline]
pub fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - n * (2.0 * d.dot(n))
}

/// The transmitted direction of the unit direction `d` through a surface whose unit normal `n`
/// faces the incoming ray (`d · n <= 0`), where `eta` is the ratio of the refractive indices
/// (incident over transmitted). Returns `None` on total internal reflection, with the cosine of
/// the transmitted angle otherwise.
#[inline]
pub fn refract(d: Vec3, n: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let cos_i = -d.dot(n);
    if eta == 1.0 {
        // Matched indices: the ray goes straight on, exactly.
        return Some((d, cos_i));
    }
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((d * eta + n * (eta * cos_i - cos_t), cos_t))
}

/// Fraction of light reflected at a dielectric boundary (unpolarised Fresnel equations), for
/// incident and transmitted cosines `cos_i`, `cos_t` and ratio `eta` (incident over transmitted).
/// Exactly zero for matched indices.
#[inline]
pub fn fresnel_dielectric(cos_i: f32, cos_t: f32, eta: f32) -> f32 {
    if eta == 1.0 {
        return 0.0;
    }
    // With n_i / n_t = eta: r_s = (eta cos_i - cos_t) / (eta cos_i + cos_t),
    //                       r_p = (cos_i - eta cos_t) / (cos_i + eta cos_t).
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    (0.5 * (rs * rs + rp * rp)).clamp(0.0, 1.0)
}

/// A point just off the surface at `p` on the side the unit normal `n` points to, so that a ray
/// leaving from it does not hit the surface it starts on.
///
/// Wächter and Binder (2019), "A Fast and Robust Method for Avoiding Self-Intersection" (Ray
/// Tracing Gems, chapter 6): the offset is a fixed number of units in the last place of each
/// coordinate, so it scales with the coordinates' magnitude, with a small absolute offset near
/// the origin where ulps vanish.
#[inline]
pub fn offset_ray_origin(p: Vec3, n: Vec3) -> Vec3 {
    const ORIGIN: f32 = 1.0 / 32.0;
    const FLOAT_SCALE: f32 = 1.0 / 65536.0;
    const INT_SCALE: f32 = 256.0;
    let offset = |p: f32, n: f32| -> f32 {
        if p.abs() < ORIGIN {
            return p + FLOAT_SCALE * n;
        }
        let ulps = (INT_SCALE * n) as i32;
        // Moving the bit pattern away from zero grows the magnitude; towards zero shrinks it.
        let ulps = if p < 0.0 { -ulps } else { ulps };
        f32::from_bits((p.to_bits() as i32).wrapping_add(ulps) as u32)
    };
    Vec3::new(offset(p.x, n.x), offset(p.y, n.y), offset(p.z, n.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mirror_reflects_at_the_mirrored_angle() {
        let d = Vec3::new(1.0, -1.0, 0.0).normalize();
        let r = reflect(d, Vec3::Y);
        assert!((r - Vec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-6);
        assert!((r.dot(Vec3::Y) + d.dot(Vec3::Y)).abs() < 1e-6, "equal angles to the normal");
    }

    #[test]
    fn snell_law_holds() {
        let d = Vec3::new(30f32.to_radians().sin(), -30f32.to_radians().cos(), 0.0);
        let (t, cos_t) = refract(d, Vec3::Y, 1.0 / 1.5).unwrap();
        let sin_t = t.x;
        assert!((30f32.to_radians().sin() - 1.5 * sin_t).abs() < 1e-6, "n1 sin i = n2 sin t");
        assert!((t.length() - 1.0).abs() < 1e-6);
        assert!((cos_t - (-t.y)).abs() < 1e-6);
    }

    #[test]
    fn total_internal_reflection_past_the_critical_angle() {
        // Glass to air, ior 1.5: critical angle asin(1/1.5) = 41.8 degrees.
        let critical = (1.0f32 / 1.5).asin().to_degrees();
        for (angle, tir) in [(critical - 0.5, false), (critical + 0.5, true), (80.0, true), (10.0, false)] {
            let a = f32::to_radians(angle);
            let d = Vec3::new(a.sin(), -a.cos(), 0.0);
            assert_eq!(refract(d, Vec3::Y, 1.5).is_none(), tir, "at {angle} degrees");
        }
    }

    #[test]
    fn fresnel_limits() {
        // Normal incidence air to glass: ((1 - 1.5) / (1 + 1.5))^2 = 0.04.
        assert!((fresnel_dielectric(1.0, 1.0, 1.0 / 1.5) - 0.04).abs() < 1e-6);
        assert_eq!(fresnel_dielectric(0.3, 0.3, 1.0), 0.0);
        // Grazing incidence reflects almost everything.
        let (_, cos_t) = refract(Vec3::new(0.9999, -0.0141, 0.0).normalize(), Vec3::Y, 1.0 / 1.5).unwrap();
        assert!(fresnel_dielectric(0.0141, cos_t, 1.0 / 1.5) > 0.9);
    }

    #[test]
    fn matched_indices_go_straight_on() {
        let d = Vec3::new(0.3, -0.9, 0.1).normalize();
        assert_eq!(refract(d, Vec3::Y, 1.0).unwrap().0, d);
    }

    #[test]
    fn offset_moves_to_the_normal_side_at_every_scale() {
        for scale in [1e-3f32, 1.0, 1e3, 1e6, 1e12] {
            let p = Vec3::new(1.3, -2.7, 0.4) * scale;
            let n = Vec3::new(0.0, 1.0, 0.0);
            let q = offset_ray_origin(p, n);
            assert!(q.y > p.y, "scale {scale}");
            assert_eq!((q.x, q.z), (p.x, p.z));
            let q = offset_ray_origin(p, -n);
            assert!(q.y < p.y, "scale {scale}");
        }
    }
}
