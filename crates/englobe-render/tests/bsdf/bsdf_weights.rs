//! What `sample` returns agrees with `eval` and `pdf`: a non-delta sample's weight is
//! `eval(wo, wi) |cos θi| / pdf(wo, wi)` and its density `pdf(wo, wi)`; a delta sample goes in
//! the mirror or the Snell direction; kinds and relative indices match the sides of `wo` and
//! `wi`; a delta-only BSDF has zero `eval` and `pdf` everywhere.

use englobe::{Vec2, Vec3};
use englobe_render::bsdf::{Bsdf, SampleKind, refract};
use rand::RngExt;

use crate::bsdf_cases::{Case, rough_cases, smooth_cases};
use crate::bsdf_stats::rng;

fn close(a: f32, b: f32, rel: f32) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-6)
}

/// The index of the transmissive part of a BSDF (inside over outside).
fn ior_of(bsdf: &Bsdf) -> Option<f32> {
    match bsdf {
        Bsdf::Dielectric(d) => Some(d.eta),
        Bsdf::MetallicRoughness(m) => Some(m.ior()),
        _ => None,
    }
}

fn check(case: &Case, seed: u64) -> Result<usize, String> {
    let (bsdf, wo) = (case.bsdf, case.wo);
    let mut rng = rng(seed);
    let mut returned = 0;
    for _ in 0..4000 {
        let u_lobe: f32 = rng.random();
        let u = Vec2::new(rng.random(), rng.random());
        let Some(s) = bsdf.sample(wo, u_lobe, u) else { continue };
        returned += 1;
        let fail = |what: &str| Err(format!("{what}: {s:?} from {wo}"));
        if !((s.wi.length() - 1.0).abs() < 1e-4 && s.weight.is_finite() && s.weight.min_element() >= 0.0) {
            return fail("not a unit direction with a finite non-negative weight");
        }
        if !(s.pdf > 0.0 && s.pdf.is_finite()) {
            return fail("density not positive");
        }
        let reflected = wo.z * s.wi.z > 0.0;
        if reflected != (s.kind == SampleKind::Reflection) {
            return fail("kind does not match the sides");
        }
        match (s.kind, ior_of(&bsdf)) {
            (SampleKind::Reflection, _) if s.eta != 1.0 => return fail("a reflection's eta is not 1"),
            (SampleKind::Transmission, None) => return fail("a reflector transmitted"),
            (SampleKind::Transmission, Some(ior)) => {
                let expected = if wo.z > 0.0 { ior } else { 1.0 / ior };
                if !close(s.eta, expected, 1e-6) {
                    return fail("eta is not n(wi side) / n(wo side)");
                }
            }
            _ => {}
        }
        if s.delta {
            let expected = match s.kind {
                SampleKind::Reflection => Vec3::new(-wo.x, -wo.y, wo.z),
                SampleKind::Transmission => refract(wo, Vec3::Z, ior_of(&bsdf).unwrap()).unwrap().0,
            };
            if (s.wi - expected).length() > 1e-5 {
                return fail("a delta sample off the mirror or Snell direction");
            }
            continue;
        }
        let (f, pdf) = (bsdf.eval(wo, s.wi), bsdf.pdf(wo, s.wi));
        if !close(s.pdf, pdf, 2e-4) {
            return Err(format!("sample pdf {} against pdf() {pdf}: {s:?}", s.pdf));
        }
        let expected = f * s.wi.z.abs() / pdf;
        for c in 0..3 {
            if !close(s.weight[c], expected[c], 2e-4) {
                return Err(format!("weight {} against f |cos| / pdf = {expected}: {s:?}", s.weight));
            }
        }
    }
    Ok(returned)
}

#[test]
fn bsdf_sample_weights_are_eval_times_cosine_over_pdf() {
    let mut failures = Vec::new();
    for (k, case) in rough_cases().iter().chain(smooth_cases().iter()).enumerate() {
        match check(case, 100 + k as u64) {
            Ok(n) if n < 1000 => failures.push(format!("{}: only {n} of 4000 samples came back", case.name)),
            Ok(_) => {}
            Err(e) => failures.push(format!("{}: {e}", case.name)),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn bsdf_delta_only_models_have_no_density() {
    let mut r = rng(7);
    for case in smooth_cases() {
        if !case.bsdf.is_delta() {
            continue;
        }
        for _ in 0..200 {
            let wi = Vec3::new(r.random::<f32>() - 0.5, r.random::<f32>() - 0.5, r.random::<f32>() - 0.5).normalize();
            assert_eq!(case.bsdf.eval(case.wo, wi), Vec3::ZERO, "{}", case.name);
            assert_eq!(case.bsdf.pdf(case.wo, wi), 0.0, "{}", case.name);
        }
        let s = case.bsdf.sample(case.wo, 0.3, Vec2::new(0.2, 0.7)).unwrap();
        assert!(s.delta, "{}", case.name);
    }
    assert!(
        !Bsdf::metallic_roughness(Vec3::ONE, 0.0, 0.0, 0.0, 1.5).is_delta(),
        "smooth plastic keeps its diffuse base"
    );
    assert!(Bsdf::metallic_roughness(Vec3::ONE, 1.0, 0.0, 0.0, 1.5).is_delta());
}

#[test]
fn bsdf_grazing_and_degenerate_directions_give_no_nan() {
    let mut cases = rough_cases();
    cases.extend(smooth_cases());
    let odd =
        [Vec3::X, Vec3::new(1.0, 0.0, 1e-7).normalize(), Vec3::Z, -Vec3::Z, Vec3::new(0.0, -1.0, -1e-6).normalize()];
    for case in &cases {
        for wo in odd {
            for wi in odd {
                let (f, pdf) = (case.bsdf.eval(wo, wi), case.bsdf.pdf(wo, wi));
                assert!(f.is_finite() && f.min_element() >= 0.0 && pdf.is_finite() && pdf >= 0.0, "{}", case.name);
            }
            for u in [0.0, 0.5, 0.999_999_9] {
                if let Some(s) = case.bsdf.sample(wo, u, Vec2::new(u, 1.0 - u)) {
                    assert!(s.weight.is_finite() && s.pdf.is_finite() && s.wi.is_finite(), "{}: {s:?}", case.name);
                }
            }
        }
    }
}
