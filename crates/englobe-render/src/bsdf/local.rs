//! Spherical trigonometry of unit directions in the local shading frame (`z` the normal), and
//! the mirror and Snell directions there. The formulas are those of Pharr, Jakob and Humphreys,
//! "Physically Based Rendering", 4th edition, sections 3.8.3 and 9.3-9.5.

use englobe::Vec3;

/// `cos θ` of a local direction.
#[inline]
pub fn cos_theta(w: Vec3) -> f32 {
    w.z
}

/// `|cos θ|` of a local direction.
#[inline]
pub fn abs_cos_theta(w: Vec3) -> f32 {
    w.z.abs()
}

/// `cos² θ` of a local direction.
#[inline]
pub fn cos2_theta(w: Vec3) -> f32 {
    w.z * w.z
}

/// `sin² θ`, never negative.
#[inline]
pub fn sin2_theta(w: Vec3) -> f32 {
    (1.0 - cos2_theta(w)).max(0.0)
}

/// `tan² θ`: infinite on the horizon.
#[inline]
pub fn tan2_theta(w: Vec3) -> f32 {
    sin2_theta(w) / cos2_theta(w)
}

/// `cos φ`, and 1 at the poles where `φ` is undefined.
#[inline]
pub fn cos_phi(w: Vec3) -> f32 {
    let sin_theta = sin2_theta(w).sqrt();
    if sin_theta == 0.0 { 1.0 } else { (w.x / sin_theta).clamp(-1.0, 1.0) }
}

/// `sin φ`, and 0 at the poles.
#[inline]
pub fn sin_phi(w: Vec3) -> f32 {
    let sin_theta = sin2_theta(w).sqrt();
    if sin_theta == 0.0 { 0.0 } else { (w.y / sin_theta).clamp(-1.0, 1.0) }
}

/// True if both directions lie strictly on the same side of the surface.
#[inline]
pub fn same_hemisphere(a: Vec3, b: Vec3) -> bool {
    a.z * b.z > 0.0
}

/// The mirror image of `wo` about the unit vector `n` (both pointing away from the surface).
#[inline]
pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    -wo + n * (2.0 * wo.dot(n))
}

/// The direction refracted from `wo` through a surface with unit normal `n`, both pointing away
/// from the surface, where `eta` is the relative index `n_below / n_above` of the side `n` points
/// away from over the side it points to. `wo` may lie on either side of `n`: below it the
/// relative index is inverted. Returns the refracted direction (on the other side of the
/// surface, unit) and the relative index `etap = n_t / n_i` of that crossing, or `None` on total
/// internal reflection.
#[inline]
pub fn refract(wo: Vec3, n: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let (mut n, mut eta, mut cos_i) = (n, eta, n.dot(wo));
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
        n = -n;
    }
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    Some((-wo / eta + n * (cos_i / eta - cos_t), eta))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(theta_deg: f32, phi_deg: f32) -> Vec3 {
        let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
        Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
    }

    #[test]
    fn angles_come_back() {
        let w = dir(30.0, 120.0);
        assert!((cos_theta(w) - 30f32.to_radians().cos()).abs() < 1e-6);
        assert!((tan2_theta(w) - 30f32.to_radians().tan().powi(2)).abs() < 1e-5);
        assert!((cos_phi(w) - 120f32.to_radians().cos()).abs() < 1e-5);
        assert!((sin_phi(w) - 120f32.to_radians().sin()).abs() < 1e-5);
        assert_eq!((cos_phi(Vec3::Z), sin_phi(Vec3::Z)), (1.0, 0.0));
        assert!(tan2_theta(Vec3::X).is_infinite());
    }

    #[test]
    fn snell_and_the_critical_angle() {
        // From air (above) into glass (below), 80 degrees: sin t = sin 80 / 1.5, t = 41.0364 degrees.
        let wo = dir(80.0, 0.0);
        let (wt, etap) = refract(wo, Vec3::Z, 1.5).unwrap();
        assert_eq!(etap, 1.5);
        assert!(wt.z < 0.0 && (wt.length() - 1.0).abs() < 1e-6);
        let t = (-wt.z).acos().to_degrees();
        assert!((t - 41.036_41).abs() < 1e-3, "{t}");
        assert!(wt.x < 0.0, "the refracted ray goes on across the normal");
        // Back out from inside: the same path reversed.
        let (back, etap_back) = refract(wt, Vec3::Z, 1.5).unwrap();
        assert!((etap_back - 1.0 / 1.5).abs() < 1e-7);
        assert!((back - wo).length() < 1e-5, "{back} against {wo}");
        // Total internal reflection from inside beyond asin(1 / 1.5) = 41.8103 degrees.
        assert!(refract(-dir(41.7, 0.0), Vec3::Z, 1.5).is_some());
        assert!(refract(-dir(41.9, 0.0), Vec3::Z, 1.5).is_none());
    }

    #[test]
    fn reflection_keeps_the_angle() {
        let wo = dir(50.0, 10.0);
        let wi = reflect(wo, Vec3::Z);
        assert!((wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
    }
}
