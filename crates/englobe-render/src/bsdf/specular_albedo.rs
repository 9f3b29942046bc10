//! The directional albedo of a rough specular layer with Schlick's Fresnel, tabulated once: the
//! energy that glTF's dielectric specular lobe reflects from each direction, which the diffuse
//! base beneath it must not reflect again.
//!
//! With Schlick's `F = F0 + (1 - F0) s`, `s = (1 - |wo·m|)^5`, the albedo of the microfacet lobe
//! `E(μ, α, F0) = ∫ F D G2 / (4 |cos θo| |cos θi|) |cos θi| dwi` is linear in `F0`:
//! `E = F0 A(μ, α) + (1 - F0) B(μ, α)`, with `A` the albedo without Fresnel and `B` the albedo
//! weighted by `s`. Both are tabulated on a uniform grid over `sqrt(μ)`, `μ = |cos θo|` (dense
//! toward grazing angles, where a smooth layer's albedo changes fastest), and the perceptual
//! roughness `sqrt(α)`, and read back bilinearly; their cosine-weighted hemispherical means
//! `Ā = 2 ∫ A μ dμ` are integrated exactly over the interpolant, so that a layer normalised by
//! `1 - Ē` reflects exactly what its table says. This is the precomputed
//! albedo of Kelemen and Szirmay-Kalos (2001), "A Microfacet Based Coupled Specular-Matte BRDF
//! Model with Importance Sampling", as Kulla and Conty (2017), "Revisiting Physically Based
//! Shading at Imageworks" (SIGGRAPH course) use it to layer a diffuse base under a specular one.
//!
//! Each entry is the mean of the sampling weight `F G2 / G1(wo)` over a stratified grid of
//! visible normals (an exact estimator of the integral above, Heitz 2018), computed once per
//! process on first use.

use std::sync::OnceLock;

use englobe::{Vec2, Vec3};

use super::fresnel::schlick_weight;
use super::local::reflect;
use super::microfacet::{SMOOTH_ALPHA, TrowbridgeReitz};

/// Grid points along `sqrt(μ)`, `μ = |cos θo|`, from 0 to 1.
const MU_POINTS: usize = 64;
/// Grid points along the perceptual roughness `sqrt(α)`, from 0 to 1.
const ROUGHNESS_POINTS: usize = 32;
/// Strata per axis of the visible-normal samples of one entry.
const STRATA: usize = 64;

/// The tables `A` and `B` and their hemispherical means.
struct Tables {
    /// `A[r][μ]` and `B[r][μ]`, row-major by roughness.
    a: Vec<f32>,
    b: Vec<f32>,
    a_mean: Vec<f32>,
    b_mean: Vec<f32>,
}

fn tables() -> &'static Tables {
    static TABLES: OnceLock<Tables> = OnceLock::new();
    TABLES.get_or_init(build)
}

fn build() -> Tables {
    let (mut a, mut b) = (Vec::with_capacity(MU_POINTS * ROUGHNESS_POINTS), Vec::new());
    for ri in 0..ROUGHNESS_POINTS {
        let roughness = ri as f32 / (ROUGHNESS_POINTS - 1) as f32;
        let alpha = roughness * roughness;
        for mi in 0..MU_POINTS {
            // The grazing column is the limit: taken just above the horizon.
            let s = mi as f32 / (MU_POINTS - 1) as f32;
            let mu = (s * s).max(1e-6);
            let (ea, eb) = if alpha < SMOOTH_ALPHA { (1.0, schlick_weight(mu)) } else { integrate(mu, alpha) };
            a.push(ea);
            b.push(eb);
        }
    }
    let means =
        |t: &[f32]| (0..ROUGHNESS_POINTS).map(|ri| hemispherical_mean(&t[ri * MU_POINTS..][..MU_POINTS])).collect();
    let (a_mean, b_mean) = (means(&a), means(&b));
    Tables { a, b, a_mean, b_mean }
}

/// `A` and `B` at one grid point, by stratified visible-normal sampling.
fn integrate(mu: f32, alpha: f32) -> (f32, f32) {
    let distribution = TrowbridgeReitz::isotropic(alpha);
    let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let g1 = distribution.g1(wo);
    let (mut sa, mut sb) = (0.0f64, 0.0f64);
    for i in 0..STRATA {
        for j in 0..STRATA {
            let u = Vec2::new((i as f32 + 0.5) / STRATA as f32, (j as f32 + 0.5) / STRATA as f32);
            let wm = distribution.sample_visible(wo, u);
            let wi = reflect(wo, wm);
            if wi.z <= 0.0 {
                continue;
            }
            let weight = (distribution.g2(wo, wi) / g1) as f64;
            sa += weight;
            sb += weight * schlick_weight(wo.dot(wm)) as f64;
        }
    }
    let n = (STRATA * STRATA) as f64;
    ((sa / n) as f32, (sb / n) as f32)
}

/// `2 ∫₀¹ E(μ) μ dμ` of the function linear in `s = sqrt(μ)` between `values` at uniform `s`,
/// exactly: with `μ = s²`, `2 ∫ E μ dμ = 4 ∫ E(s) s³ ds`.
fn hemispherical_mean(values: &[f32]) -> f32 {
    let h = 1.0 / (values.len() - 1) as f64;
    let mut sum = 0.0;
    for (k, pair) in values.windows(2).enumerate() {
        let (s0, s1) = (k as f64 * h, (k + 1) as f64 * h);
        let (e0, e1) = (pair[0] as f64, pair[1] as f64);
        // ∫ s³ ds and ∫ (s - s0) s³ ds over [s0, s1]; E = e0 + (e1 - e0)(s - s0) / h.
        let m3 = (s1.powi(4) - s0.powi(4)) / 4.0;
        let m4 = (s1.powi(5) - s0.powi(5)) / 5.0 - s0 * m3;
        sum += e0 * m3 + (e1 - e0) / h * m4;
    }
    (4.0 * sum) as f32
}

/// The grid cell and the fraction inside it of `x` in `[0, 1]` over `points` nodes.
fn cell(x: f32, points: usize) -> (usize, f32) {
    let s = x.clamp(0.0, 1.0) * (points - 1) as f32;
    let i = (s as usize).min(points - 2);
    (i, s - i as f32)
}

/// The albedo `E(μ, α, F0)` of the specular lobe with Schlick's Fresnel of normal reflectance
/// `f0`, for `μ = |cos θo|` and the microfacet `alpha` (isotropic).
pub fn specular_albedo(mu: f32, alpha: f32, f0: f32) -> f32 {
    let (a, b) = albedo_parts(mu, alpha);
    f0 * a + (1.0 - f0) * b
}

/// `(A, B)` at `μ = |cos θo|` and `alpha`: the albedo is `F0 A + (1 - F0) B`.
pub fn albedo_parts(mu: f32, alpha: f32) -> (f32, f32) {
    let t = tables();
    let (ri, fr) = cell(alpha.max(0.0).sqrt(), ROUGHNESS_POINTS);
    let (mi, fm) = cell(mu.abs().min(1.0).sqrt(), MU_POINTS);
    let bilinear = |v: &[f32]| {
        let row = |r: usize| v[r * MU_POINTS + mi] * (1.0 - fm) + v[r * MU_POINTS + mi + 1] * fm;
        row(ri) * (1.0 - fr) + row(ri + 1) * fr
    };
    (bilinear(&t.a), bilinear(&t.b))
}

/// The cosine-weighted hemispherical mean `Ē = 2 ∫ E(μ) μ dμ` of [`specular_albedo`], exact for
/// its interpolated table.
pub fn mean_specular_albedo(alpha: f32, f0: f32) -> f32 {
    let t = tables();
    let (ri, fr) = cell(alpha.max(0.0).sqrt(), ROUGHNESS_POINTS);
    let lerp = |v: &[f32]| v[ri] * (1.0 - fr) + v[ri + 1] * fr;
    f0 * lerp(&t.a_mean) + (1.0 - f0) * lerp(&t.b_mean)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_smooth_layer_reflects_schlick_s_fresnel() {
        for mu in [0.05f32, 0.3, 0.7, 1.0] {
            let f = 0.04 + 0.96 * schlick_weight(mu);
            assert!((specular_albedo(mu, 0.0, 0.04) - f).abs() < 3e-3, "{mu}");
        }
        // Ā of the smooth Schlick layer: F0 + (1 - F0) 2 ∫ (1 - μ)^5 μ dμ = F0 + (1 - F0) / 21.
        assert!((mean_specular_albedo(0.0, 0.04) - (0.04 + 0.96 / 21.0)).abs() < 1e-3);
    }

    #[test]
    fn rough_layers_lose_energy_as_closed_forms_say() {
        // Without Fresnel the single-scattering albedo is 1 for a smooth surface and falls with
        // roughness.
        let (a_smooth, _) = albedo_parts(0.5, 0.0);
        assert!((a_smooth - 1.0).abs() < 1e-6);
        // At alpha = 1, D = 1 / π and Λ(w) = (1 / cos θ - 1) / 2, so from the normal
        // A = ∫ 2 cos θi / (1 + cos θi) / (4π) dwi = 1 - ln 2.
        // Weighted by (1 - wo·m)^5 with wo·m = cos(θi / 2): B = ∫ c / (1 + c) (1 - sqrt((1 + c) / 2))^5 dc
        // = 3.36143e-5 (by quadrature in double precision).
        let (a_normal, b_normal) = albedo_parts(1.0, 1.0);
        assert!((a_normal - (1.0 - std::f32::consts::LN_2)).abs() < 1e-4, "{a_normal}");
        assert!((b_normal - 3.361_43e-5).abs() < 1e-6, "{b_normal}");
        let (a_half, _) = albedo_parts(0.5, 0.25);
        assert!(a_half > 0.85 && a_half < 0.99, "{a_half}");
        for ri in 0..ROUGHNESS_POINTS {
            for mi in 0..MU_POINTS {
                let (a, b) = (tables().a[ri * MU_POINTS + mi], tables().b[ri * MU_POINTS + mi]);
                assert!((0.0..=1.0 + 1e-6).contains(&a) && (0.0..=a + 1e-6).contains(&b), "{ri} {mi}: {a} {b}");
            }
        }
    }

    #[test]
    fn the_mean_is_exact_for_the_interpolant() {
        // E = sqrt(μ) (a line in s): 2 ∫ μ^1.5 dμ = 4/5; E = 1: 1.
        let line: Vec<f32> = (0..5).map(|k| k as f32 / 4.0).collect();
        assert!((hemispherical_mean(&line) - 0.8).abs() < 1e-6);
        assert!((hemispherical_mean(&[1.0; 7]) - 1.0).abs() < 1e-6);
    }
}
