//! Helmholtz reciprocity: `f(wo, wi) = f(wi, wo)` for every reflection, and for transmission the
//! generalised reciprocity of radiance BSDFs, `f(wo, wi) n(wi)² = f(wi, wo) n(wo)²` (Veach 1997,
//! chapter 5), `n` the index on each direction's side.

use englobe::Vec3;
use englobe_render::bsdf::Bsdf;
use rand::RngExt;

use crate::bsdf_cases::rough_cases;
use crate::bsdf_stats::rng;

/// The index on `w`'s side of the surface: 1 outside, the BSDF's index inside.
fn index_on_side(bsdf: &Bsdf, w: Vec3) -> f32 {
    match bsdf {
        Bsdf::Dielectric(d) if w.z < 0.0 => d.eta,
        Bsdf::MetallicRoughness(m) if w.z < 0.0 && bsdf.has_transmission() => m.ior(),
        _ => 1.0,
    }
}

#[test]
fn bsdf_reflection_and_generalised_transmission_reciprocity() {
    let mut r = rng(11);
    let mut failures = Vec::new();
    let (mut reflections, mut transmissions) = (0, 0);
    for case in rough_cases() {
        let b = case.bsdf;
        for _ in 0..2000 {
            let mut random_dir = || {
                let v = Vec3::new(
                    r.random::<f32>() * 2.0 - 1.0,
                    r.random::<f32>() * 2.0 - 1.0,
                    r.random::<f32>() * 2.0 - 1.0,
                );
                v.normalize()
            };
            let (wo, wi) = (random_dir(), random_dir());
            if wo.z.abs() < 1e-3 || wi.z.abs() < 1e-3 {
                continue;
            }
            let (no, ni) = (index_on_side(&b, wo), index_on_side(&b, wi));
            let forward = b.eval(wo, wi) * (ni * ni);
            let backward = b.eval(wi, wo) * (no * no);
            if forward == Vec3::ZERO && backward == Vec3::ZERO {
                continue;
            }
            if wo.z * wi.z > 0.0 {
                reflections += 1
            } else {
                transmissions += 1
            }
            // Single precision, with an absolute floor for the far tails of the narrowest lobes,
            // where the two half vectors, computed from differently scaled sums, cancel.
            let scale = forward.max_element().max(backward.max_element());
            if (forward - backward).abs().max_element() > 2e-4 * scale + 1e-6 {
                failures
                    .push(format!("{}: f({wo}, {wi}) n_i² = {forward}, f({wi}, {wo}) n_o² = {backward}", case.name));
            }
        }
    }
    assert!(reflections > 10_000 && transmissions > 2_000, "{reflections} {transmissions}");
    assert!(failures.is_empty(), "{} pairs:\n{}", failures.len(), failures.join("\n"));
}
