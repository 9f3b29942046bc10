//! Closed forms: the Fresnel equations through the sampler of a smooth dielectric (normal
//! incidence, 80 degrees, Brewster's angle, Snell's law, total internal reflection), GGX's
//! normalisation and the projected-area identity of its visible normals, smooth conductors as
//! mirrors, and glTF's limits (a smooth metal is a mirror of Schlick's Fresnel from the base
//! colour).

use std::f64::consts::PI;

use englobe::{Vec2, Vec3};
use englobe_render::bsdf::{Bsdf, SampleKind, TrowbridgeReitz, fresnel_complex_rgb};
use rand::RngExt;

use crate::bsdf_cases::{GOLD_ETA, GOLD_K};
use crate::bsdf_stats::{cell_probabilities, dir, rng};

/// The fraction of a smooth dielectric's samples that reflect, which must be the Fresnel
/// reflectance; and the transmitted direction.
fn smooth_glass(wo: Vec3) -> (f64, f64, Option<Vec3>) {
    let glass = Bsdf::dielectric(1.5, TrowbridgeReitz::isotropic(0.0));
    let mut r = rng(21);
    let n = 200_000;
    let (mut reflected, mut transmitted) = (0usize, None);
    for _ in 0..n {
        let s = glass.sample(wo, r.random(), Vec2::new(r.random(), r.random())).unwrap();
        assert!(s.delta);
        match s.kind {
            SampleKind::Reflection => reflected += 1,
            SampleKind::Transmission => transmitted = Some(s.wi),
        }
    }
    let p = reflected as f64 / n as f64;
    (p, (p * (1.0 - p) / n as f64).sqrt(), transmitted)
}

#[test]
fn bsdf_smooth_dielectric_reflects_with_the_fresnel_probability() {
    let brewster = 1.5f64.atan().to_degrees();
    for (theta, fresnel) in [(0.0, 0.04), (80.0, 0.387_704_354_691_473), (brewster, 25.0 / 338.0)] {
        let (p, se, t) = smooth_glass(dir(theta, 0.0));
        assert!((p - fresnel).abs() < 5.0 * se + 1e-6, "{theta}: {p} ± {se} against {fresnel}");
        let t = t.unwrap();
        if theta == 80.0 {
            let refracted = (-t.z as f64).acos().to_degrees();
            assert!((refracted - 41.036_410_525_203_35).abs() < 1e-3, "{refracted}");
        }
    }
    // From inside: total internal reflection beyond 41.8103 degrees.
    let (p, _, _) = smooth_glass(dir(180.0 - 41.9, 0.0));
    assert_eq!(p, 1.0);
    let (p, _, t) = smooth_glass(dir(180.0 - 41.7, 0.0));
    assert!(p < 1.0 && t.unwrap().z > 0.0);
}

#[test]
fn bsdf_ggx_is_normalised() {
    for m in [
        TrowbridgeReitz::isotropic(0.05),
        TrowbridgeReitz::isotropic(0.2),
        TrowbridgeReitz::isotropic(0.6),
        TrowbridgeReitz::isotropic(1.0),
        TrowbridgeReitz::new(0.1, 0.7),
    ] {
        // ∫ D(m) cos θm dm = 1: the microsurface projects onto the macrosurface's area.
        let projected: f64 = cell_probabilities(&|w| (m.d(w) * w.z.max(0.0)) as f64, 1e-8).iter().sum();
        assert!((projected - 1.0).abs() < 1e-4, "{m:?}: {projected}");
        for wo in [dir(0.0, 0.0), dir(45.0, 20.0), dir(80.0, 110.0), dir(130.0, 60.0)] {
            // ∫ D_wo(m) dm = 1, and the projected-area identity ∫ D(m) max(0, wo·m) dm =
            // |cos θo| (1 + Λ(wo)) (Heitz 2014, section 3), which ties Λ to D.
            let visible: f64 = cell_probabilities(&|w| m.d_visible(wo, w) as f64, 1e-8).iter().sum();
            assert!((visible - 1.0).abs() < 1e-4, "{m:?} from {wo}: {visible}");
            let up = if wo.z < 0.0 { -wo } else { wo };
            let area: f64 = cell_probabilities(&|w| (m.d(w) * up.dot(w).max(0.0)) as f64, 1e-8).iter().sum();
            let expected = (up.z * (1.0 + m.lambda(up))) as f64;
            assert!((area - expected).abs() < 1e-4 * expected, "{m:?} from {wo}: {area} against {expected}");
        }
    }
    // The isotropic D at the pole and the Λ of a hand value, in double precision.
    let alpha = 0.4f64;
    let m = TrowbridgeReitz::isotropic(alpha as f32);
    assert!((m.d(Vec3::Z) as f64 - 1.0 / (PI * alpha * alpha)).abs() < 1e-5 / (alpha * alpha));
}

#[test]
fn bsdf_smooth_conductors_are_mirrors_of_their_fresnel() {
    let gold = Bsdf::conductor(GOLD_ETA, GOLD_K, TrowbridgeReitz::isotropic(0.0));
    for theta in [0.0, 30.0, 60.0, 89.0] {
        let wo = dir(theta, 70.0);
        let s = gold.sample(wo, 0.5, Vec2::new(0.3, 0.3)).unwrap();
        assert!(s.delta && (s.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
        assert!((s.weight - fresnel_complex_rgb(wo.z, GOLD_ETA, GOLD_K)).abs().max_element() < 1e-6);
    }
}

#[test]
fn bsdf_gltf_smooth_metal_is_a_mirror_of_its_base_colour() {
    let base = Vec3::new(0.95, 0.64, 0.54);
    for roughness in [0.0, 0.01, 0.03] {
        let mirror = Bsdf::metallic_roughness(base, 1.0, roughness, 0.0, 1.5);
        assert!(mirror.is_delta(), "roughness {roughness}");
        for (theta, weight) in [(0.0, base), (60.0, base + (Vec3::ONE - base) / 32.0)] {
            let wo = dir(theta, 0.0);
            for u_lobe in [0.0, 0.5, 0.99] {
                let s = mirror.sample(wo, u_lobe, Vec2::new(0.4, 0.6)).unwrap();
                assert!(s.delta && (s.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-5);
                assert!((s.weight - weight).abs().max_element() < 1e-5, "{theta}: {} against {weight}", s.weight);
            }
        }
    }
    // Just rough enough not to be a delta: it reflects the same energy, spread about the mirror.
    let rough = Bsdf::metallic_roughness(base, 1.0, 0.05, 0.0, 1.5);
    assert!(!rough.is_delta());
    // GGX's tails are long: a facet tilts beyond t = tan 2.5° with probability α² / (α² + t²),
    // 0.33 % at α = 0.0025.
    let mut r = rng(5);
    let (mut sum, mut near, n) = (Vec3::ZERO, 0, 20_000);
    for _ in 0..n {
        if let Some(s) = rough.sample(Vec3::Z, r.random(), Vec2::new(r.random(), r.random())) {
            sum += s.weight;
            near += usize::from(s.wi.z > 5f32.to_radians().cos());
        }
    }
    assert!(near as f64 > 0.99 * n as f64, "{near} of {n} within 5 degrees of the mirror direction");
    assert!((sum / n as f32 - base).abs().max_element() < 2e-3, "{}", sum / n as f32);
}

/// An opaque glTF dielectric of index 1 has no specular layer: Lambert's `base / π` at every
/// angle, grazing ones included, where Schlick's approximation of a layer would add
/// `(1 - cos θ)⁵`; a layer of 1.5 reflects more than that at 85 degrees.
#[test]
fn bsdf_gltf_dielectric_of_index_one_is_lambert() {
    let base = Vec3::new(0.6, 0.3, 0.1);
    let plain = Bsdf::metallic_roughness(base, 0.0, 0.4, 0.0, 1.0);
    assert_eq!(plain, Bsdf::lambert(base));
    let lambert = base / std::f32::consts::PI;
    let (wo, wi) = (dir(85.0, 0.0), dir(85.0, 180.0));
    assert!((plain.eval(wo, wi) - lambert).abs().max_element() < 1e-6);
    let coated = Bsdf::metallic_roughness(base, 0.0, 0.4, 0.0, 1.5);
    assert!(coated.eval(wo, wi).z > 2.0 * lambert.z, "{}", coated.eval(wo, wi));
    // A metal or a transmitting dielectric of index 1 keeps the glTF model.
    assert_ne!(Bsdf::metallic_roughness(base, 0.5, 0.4, 0.0, 1.0), Bsdf::lambert(base));
}
