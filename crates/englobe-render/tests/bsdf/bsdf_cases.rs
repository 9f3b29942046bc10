//! The BSDFs and incident directions the tests run over: every model, smooth and rough, a few
//! roughnesses (isotropic and anisotropic), incidence near the normal, oblique and grazing, from
//! outside and from inside the transmissive ones.

use englobe::Vec3;
use englobe_render::bsdf::{Bsdf, TrowbridgeReitz};

use crate::bsdf_stats::dir;

/// A BSDF seen from one direction.
pub struct Case {
    pub name: String,
    pub bsdf: Bsdf,
    pub wo: Vec3,
}

impl Case {
    fn new(name: String, bsdf: Bsdf, wo: Vec3) -> Case {
        Case { name, bsdf, wo }
    }
}

/// Gold's complex index at the red, green and blue primaries (pbrt-v4's `metal-Au`, roughly).
pub const GOLD_ETA: Vec3 = Vec3::new(0.143, 0.374, 1.442);
pub const GOLD_K: Vec3 = Vec3::new(3.983, 2.385, 1.603);

/// Outside incidence angles, degrees from the normal.
const OUTSIDE: [f64; 3] = [10.0, 50.0, 80.0];
/// Roughness `alpha`s of the rough cases.
const ALPHAS: [f32; 3] = [0.05, 0.3, 1.0];

/// The rough, non-delta cases: what the chi-square tests fit, grouped by family.
pub fn lambert_cases() -> Vec<Case> {
    let b = Bsdf::lambert(Vec3::new(0.8, 0.5, 0.2));
    vec![Case::new("lambert 30".into(), b, dir(30.0, 20.0)), Case::new("lambert below".into(), b, dir(120.0, 200.0))]
}

pub fn conductor_cases() -> Vec<Case> {
    let mut cases = Vec::new();
    for alpha in ALPHAS {
        for theta in OUTSIDE {
            let b = Bsdf::conductor(GOLD_ETA, GOLD_K, TrowbridgeReitz::isotropic(alpha));
            cases.push(Case::new(format!("gold alpha {alpha} at {theta}"), b, dir(theta, 40.0)));
        }
    }
    for (ax, ay, theta) in [(0.1, 0.5, 30.0), (0.6, 0.08, 70.0)] {
        let b = Bsdf::conductor(GOLD_ETA, GOLD_K, TrowbridgeReitz::new(ax, ay));
        cases.push(Case::new(format!("gold alpha ({ax}, {ay}) at {theta}"), b, dir(theta, 65.0)));
    }
    let schlick = Bsdf::conductor_schlick(Vec3::new(0.95, 0.64, 0.54), TrowbridgeReitz::isotropic(0.3));
    cases.push(Case::new("schlick copper at 45".into(), schlick, dir(45.0, 10.0)));
    cases.push(Case::new("schlick copper below".into(), schlick, dir(135.0, 100.0)));
    cases
}

pub fn dielectric_cases() -> Vec<Case> {
    let mut cases = Vec::new();
    for alpha in ALPHAS {
        let b = Bsdf::dielectric(1.5, TrowbridgeReitz::isotropic(alpha));
        for theta in OUTSIDE {
            cases.push(Case::new(format!("glass alpha {alpha} at {theta}"), b, dir(theta, 30.0)));
        }
        // Inside: below and beyond the critical angle of 41.8 degrees.
        for theta in [20.0, 60.0] {
            cases.push(Case::new(format!("glass alpha {alpha} inside at {theta}"), b, dir(180.0 - theta, 30.0)));
        }
    }
    let water = Bsdf::dielectric(1.33, TrowbridgeReitz::isotropic(0.5));
    cases.push(Case::new("water alpha 0.5 at 60".into(), water, dir(60.0, 0.0)));
    let brushed = Bsdf::dielectric(1.5, TrowbridgeReitz::new(0.05, 0.4));
    cases.push(Case::new("glass alpha (0.05, 0.4) at 40".into(), brushed, dir(40.0, 75.0)));
    cases.push(Case::new("glass alpha (0.05, 0.4) inside at 30".into(), brushed, dir(150.0, 75.0)));
    cases
}

/// glTF metallic-roughness: `(base colour, metallic, roughness, transmission, ior)`.
pub fn metallic_roughness_cases() -> Vec<Case> {
    let orange = Vec3::new(0.9, 0.5, 0.1);
    let params: [(Vec3, f32, f32, f32, f32); 8] = [
        (orange, 0.0, 0.5, 0.0, 1.5),
        (Vec3::ONE, 0.0, 0.9, 0.0, 1.5),
        (orange, 1.0, 0.5, 0.0, 1.5),
        (orange, 0.5, 0.3, 0.0, 1.5),
        (Vec3::new(0.7, 0.9, 1.0), 0.0, 0.4, 1.0, 1.5),
        (orange, 0.0, 0.5, 0.5, 1.45),
        (orange, 0.3, 0.7, 0.4, 1.6),
        // Smooth: the specular lobe is a delta, the diffuse base is fitted alone.
        (orange, 0.0, 0.0, 0.0, 1.5),
    ];
    let mut cases = Vec::new();
    for (base, metallic, roughness, transmission, ior) in params {
        let b = Bsdf::metallic_roughness(base, metallic, roughness, transmission, ior);
        let name = format!("gltf m {metallic} r {roughness} t {transmission}");
        for theta in [20.0, 70.0] {
            cases.push(Case::new(format!("{name} at {theta}"), b, dir(theta, 15.0)));
        }
        if transmission > 0.0 {
            cases.push(Case::new(format!("{name} inside at 30"), b, dir(150.0, 15.0)));
        }
    }
    let plastic = Bsdf::plastic(Vec3::new(0.2, 0.6, 0.3), 0.2, 1.5);
    cases.push(Case::new("plastic alpha 0.2 at 45".into(), plastic, dir(45.0, 100.0)));
    cases
}

/// Every rough case.
pub fn rough_cases() -> Vec<Case> {
    let mut all = lambert_cases();
    all.extend(conductor_cases());
    all.extend(dielectric_cases());
    all.extend(metallic_roughness_cases());
    all
}

/// Smooth (delta) BSDFs, for the tests that do not fit densities.
pub fn smooth_cases() -> Vec<Case> {
    let smooth = TrowbridgeReitz::isotropic(0.0);
    let mut cases = Vec::new();
    for theta in [0.0, 45.0, 85.0] {
        cases.push(Case::new(
            format!("smooth gold at {theta}"),
            Bsdf::conductor(GOLD_ETA, GOLD_K, smooth),
            dir(theta, 0.0),
        ));
        cases.push(Case::new(format!("smooth glass at {theta}"), Bsdf::dielectric(1.5, smooth), dir(theta, 0.0)));
        cases.push(Case::new(
            format!("smooth glass inside at {theta}"),
            Bsdf::dielectric(1.5, smooth),
            dir(180.0 - theta, 0.0),
        ));
        let mirror = Bsdf::metallic_roughness(Vec3::new(0.9, 0.6, 0.3), 1.0, 0.0, 0.0, 1.5);
        cases.push(Case::new(format!("gltf mirror at {theta}"), mirror, dir(theta, 0.0)));
        let clear = Bsdf::metallic_roughness(Vec3::ONE, 0.0, 0.0, 1.0, 1.5);
        cases.push(Case::new(format!("gltf smooth glass at {theta}"), clear, dir(theta, 0.0)));
    }
    cases
}
