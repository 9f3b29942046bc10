//! What sampling a BSDF returns: the direction, its Monte Carlo weight and density, and what kind
//! of scattering it was (pbrt-v4's `BSDFSample`).

use englobe::Vec3;

/// Whether a sampled direction left on the side it arrived from or crossed the surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleKind {
    /// `wi` on the same side of the surface as `wo`.
    Reflection,
    /// `wi` on the other side.
    Transmission,
}

/// A direction drawn by [`crate::bsdf::Bsdf::sample`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// The sampled direction toward the light, unit, local frame.
    pub wi: Vec3,
    /// The path throughput factor `f(wo, wi) |cos θi| / pdf`, per colour channel. For a delta
    /// lobe, the lobe's reflectance or transmittance over the probability of choosing it.
    pub weight: Vec3,
    /// The density of `wi` per unit solid angle; for a delta lobe, the discrete probability of
    /// having chosen it (to be used only by the rule of [`BsdfSample::delta`]).
    pub pdf: f32,
    /// True if `wi` comes from a Dirac delta lobe (a smooth mirror or refraction): neither
    /// `eval` nor `pdf` ever see it, so next-event estimation cannot reach it and the light the
    /// path finds in that direction is taken with MIS weight 1.
    pub delta: bool,
    /// Reflection or transmission.
    pub kind: SampleKind,
    /// The relative index of refraction `n_t / n_i` crossed by a transmission (`n` being the
    /// index on each side, `wo`'s side first), 1 for a reflection. A radiance path's throughput
    /// is divided by `eta²` at each crossing (already in `weight`); the path tracer multiplies
    /// `eta²` into its Russian-roulette estimate to undo it there, as pbrt-v4's `etaScale` does.
    pub eta: f32,
}
