//! Unit directions in the local shading frame (`z` the normal): their side of the surface, and
//! the mirror and Snell directions. The formulas are those of Pharr, Jakob and Humphreys,
//! "Physically Based Rendering", 4th edition, chapters 3 and 9.

use englobe::Vec3;

/// `|cos θ|` of a local direction.
#[inline]
pub fn abs_cos_theta(w: Vec3) -> f32 {
    w.z.abs()
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
