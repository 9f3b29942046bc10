//! Chi-square goodness of fit of every BSDF's sampler against its density (pbrt-v4's
//! `bsdfs_test.cpp`, Mitsuba 3's `chi2.py`): 10^6 samples per case, cells over `(cos θ, φ)` whose
//! expected counts integrate `pdf` by adaptive quadrature, low-count cells pooled, significance
//! 0.01 for the whole family after the Šidák correction. Each case also checks that `pdf`
//! integrates to the fraction of samples that came back as directions (the rest were lost below
//! the horizon or drawn from delta lobes), within five binomial standard errors.

use englobe::{Vec2, Vec3};
use englobe_render::bsdf::TrowbridgeReitz;
use rand::RngExt;

use crate::bsdf_cases::{
    Case, conductor_cases, dielectric_cases, lambert_cases, metallic_roughness_cases, rough_cases,
};
use crate::bsdf_stats::{SAMPLES, chi2_test, dir, sidak};

/// Incident directions and distributions of the visible-normal sampler's own test.
fn vndf_cases() -> Vec<(TrowbridgeReitz, Vec3)> {
    vec![
        (TrowbridgeReitz::isotropic(0.2), dir(30.0, 0.0)),
        (TrowbridgeReitz::isotropic(0.8), dir(85.0, 10.0)),
        (TrowbridgeReitz::new(0.1, 0.6), dir(60.0, 50.0)),
        (TrowbridgeReitz::isotropic(0.5), dir(135.0, 80.0)),
    ]
}

/// Every chi-square test of this file, for the Šidák correction.
fn test_count() -> usize {
    rough_cases().len() + vndf_cases().len()
}

fn fit(cases: Vec<Case>, seed: u64) {
    let alpha = sidak(test_count());
    let mut failures = Vec::new();
    for (k, case) in cases.iter().enumerate() {
        let (bsdf, wo) = (case.bsdf, case.wo);
        let mut sample = |rng: &mut rand_pcg::Pcg32| {
            let u_lobe: f32 = rng.random();
            let u = Vec2::new(rng.random(), rng.random());
            bsdf.sample(wo, u_lobe, u).filter(|s| !s.delta).map(|s| s.wi)
        };
        let pdf = |wi: Vec3| bsdf.pdf(wo, wi) as f64;
        match chi2_test(seed + k as u64, &mut sample, &pdf) {
            Err(e) => failures.push(format!("{}: {e}", case.name)),
            Ok(out) => {
                let se = (out.accepted * (1.0 - out.accepted) / SAMPLES as f64).sqrt();
                if out.p_value < alpha {
                    let (p, chi2, dof) = (out.p_value, out.statistic, out.dof);
                    failures.push(format!("{}: p = {p:e} < {alpha:e}, chi² {chi2} on {dof} dof", case.name));
                }
                if (out.mass - out.accepted).abs() > 5.0 * se + 2e-4 || out.mass > 1.0 + 2e-4 {
                    failures.push(format!("{}: ∫ pdf = {} but {} came back", case.name, out.mass, out.accepted));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{} of {} cases failed:\n{}", failures.len(), cases.len(), failures.join("\n"));
}

#[test]
fn bsdf_chi2_lambert() {
    fit(lambert_cases(), 1000);
}

#[test]
fn bsdf_chi2_conductors() {
    fit(conductor_cases(), 2000);
}

#[test]
fn bsdf_chi2_dielectrics() {
    fit(dielectric_cases(), 3000);
}

#[test]
fn bsdf_chi2_metallic_roughness() {
    fit(metallic_roughness_cases(), 4000);
}

#[test]
fn bsdf_chi2_visible_normals() {
    let alpha = sidak(test_count());
    for (k, (m, wo)) in vndf_cases().into_iter().enumerate() {
        let mut sample = |rng: &mut rand_pcg::Pcg32| Some(m.sample_visible(wo, Vec2::new(rng.random(), rng.random())));
        let pdf = |wm: Vec3| m.d_visible(wo, wm) as f64;
        let out = chi2_test(5000 + k as u64, &mut sample, &pdf).unwrap();
        assert!(out.p_value >= alpha, "{m:?} from {wo}: {out:?}");
        assert!((out.mass - 1.0).abs() < 2e-4, "D_wo integrates to 1: {out:?}");
    }
}

/// The test has power: a sampler of roughness 0.3 is told apart from the density of 0.33.
#[test]
fn bsdf_chi2_catches_a_ten_percent_roughness_error() {
    let (sampled, claimed) = (TrowbridgeReitz::isotropic(0.3), TrowbridgeReitz::isotropic(0.33));
    let wo = dir(40.0, 0.0);
    let mut sample =
        |rng: &mut rand_pcg::Pcg32| Some(sampled.sample_visible(wo, Vec2::new(rng.random(), rng.random())));
    let pdf = |wm: Vec3| claimed.d_visible(wo, wm) as f64;
    let out = chi2_test(6000, &mut sample, &pdf).unwrap();
    assert!(out.p_value < sidak(test_count()) * 1e-6, "{out:?}");
}
