//! The scattering models of the renderer (BSDFs): Lambert, smooth and rough conductors, smooth
//! and rough dielectrics, plastic, and glTF 2.0's metallic-roughness material, over the Trowbridge-Reitz
//! (GGX) microfacet distribution with height-correlated Smith masking and visible-normal
//! sampling. Each file names the papers it implements.
//!
//! # Conventions
//!
//! - **Local frame.** Every direction is unit length and expressed in the local shading frame
//!   ([`Frame`]): `z` is the shading normal, `x` and `y` the tangents (anisotropic roughness runs
//!   along them). `cos θ = w.z`.
//! - **Directions point away from the surface.** `wo` points toward the viewer (the camera, the
//!   previous vertex of a camera path: `-ray.dir`), `wi` toward the light (the next vertex). A
//!   reflection has `wo.z` and `wi.z` of the same sign, a transmission of opposite signs.
//! - **Sides.** Reflectors (Lambert, conductor, metallic-roughness without transmission) are
//!   two-sided: `wo.z < 0` reflects exactly as its mirror image does, so the frame may face
//!   either way. A BSDF with transmission ([`Bsdf::has_transmission`]) is a boundary between an
//!   outside (`z > 0`) and an inside of relative index `eta = n_inside / n_outside`: its frame's
//!   `z` must be the outward normal, and `wo.z < 0` means the viewer is inside.
//! - **`eval(wo, wi)` is `f(wo, wi)` without any cosine.** The reflected radiance is
//!   `∫ f(wo, wi) Li(wi) |cos θi| dwi`: multiply by `|wi.z|` (in the shading frame) yourself.
//!   `eval` and `pdf` cover the non-delta lobes only (a delta lobe is zero in both).
//! - **`pdf(wo, wi)` is per unit solid angle of `wi`**, the density with which `sample` returns
//!   `wi` as a non-delta sample; it integrates to at most 1 (less where samples are lost, as
//!   microfacet reflections that fall below the horizon are, and by the probability of the
//!   delta lobes).
//! - **`sample(wo, u_lobe, u)`** returns a [`BsdfSample`]: `weight = f |cos θi| / pdf` (the
//!   factor a path's throughput is multiplied by), `pdf`, `delta` (a smooth lobe: `pdf` is then
//!   the lobe's discrete probability and MIS must not be applied), `kind` (reflection or
//!   transmission) and `eta`. Non-delta samples satisfy `weight == eval(wo, wi) |wi.z| / pdf`
//!   and `pdf == pdf(wo, wi)` (mixtures are weighted by the whole mixture's `f` and `pdf`).
//! - **Transmission carries radiance.** A transmitted `f` (and weight) includes the factor
//!   `1 / η'²`, `η' = n(wi's side) / n(wo's side)` = [`BsdfSample::eta`], as pbrt-v4's
//!   `TransportMode::Radiance`: radiance entering a denser medium is compressed into a smaller
//!   solid angle. This is right for paths traced from the camera; light paths (importance)
//!   would need `f` without it, which nothing in the renderer traces. The generalised
//!   reciprocity `f(wo, wi) n(wi)² = f(wi, wo) n(wo)²` holds.
//! - **Roughness.** Distributions take `alpha`; [`roughness_to_alpha`] is glTF's `roughness²`,
//!   [`pbrt_roughness_to_alpha`] pbrt-v4's `sqrt(roughness)` (its `remaproughness true`).
//!   Below [`SMOOTH_ALPHA`] a surface is a perfect mirror or refractor (delta lobes).
//!
//! Tests: `cargo test -p englobe-render bsdf` (unit tests here; chi-square goodness of fit,
//! energy, reciprocity and normalisation in `tests/bsdf/`).

mod conductor;
mod dielectric;
mod dispatch;
mod frame;
mod fresnel;
mod lambert;
mod local;
mod metallic_roughness;
mod microfacet;
mod sample;
mod specular_albedo;

pub use conductor::{Conductor, ConductorFresnel};
pub use dielectric::Dielectric;
pub use dispatch::Bsdf;
pub use frame::Frame;
pub use fresnel::{f0_from_ior, fresnel_complex, fresnel_complex_rgb, fresnel_dielectric, fresnel_schlick};
pub use lambert::{Lambert, cosine_hemisphere};
pub use local::{reflect, refract};
pub use metallic_roughness::MetallicRoughness;
pub use microfacet::{SMOOTH_ALPHA, TrowbridgeReitz, pbrt_roughness_to_alpha, roughness_to_alpha};
pub use sample::{BsdfSample, SampleKind};
pub use specular_albedo::{mean_specular_albedo, specular_albedo};
