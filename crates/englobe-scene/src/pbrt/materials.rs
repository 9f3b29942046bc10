//! pbrt materials (`Material`, `MakeNamedMaterial`, `NamedMaterial`) as englobe materials.
//!
//! All of the mapping is [`Builder::classic_material`], one arm per pbrt material type. pbrt-v4's
//! four common materials reach the path tracer's BSDFs (`englobe_render::bsdf`): `diffuse` is a
//! Lambertian (the classic model's diffuse lobe, exact), `conductor` a
//! [`MaterialModel::Conductor`] (the exact Fresnel equations of its complex index, Trowbridge-Reitz
//! microfacets when rough), `dielectric` a [`MaterialModel::Dielectric`] (smooth, or Walter et
//! al. 2007's rough dielectric), and `coateddiffuse` a [`MaterialModel::CoatedDiffuse`]: the
//! renderer's plastic BSDF, a deterministic stand-in for pbrt-v4's stochastic layered BSDF
//! (Guo et al. 2018, "Position-Free Monte Carlo Simulation for Arbitrary Layered BSDFs"),
//! reported as an approximation. Those materials keep a classic stand-in in their classic fields
//! for the Whitted integrator. The other types are the nearest classic material, reported with
//! the material's name and place and what was approximated.
//!
//! Roughness follows pbrt-v4: `uroughness` and `vroughness` default to `roughness`, and with
//! `remaproughness` (the default) the microfacet `alpha` is `sqrt(roughness)`
//! (`TrowbridgeReitzDistribution::RoughnessToAlpha`); a surface with `alpha < 0.001` is smooth
//! (`EffectivelySmooth`). Two different axes are rendered isotropic with their mean, reported.
//! pbrt-v3's materials (`matte`, `plastic`, `mirror`, `glass`, `metal`, `substrate`) are read too,
//! with pbrt-v3's remapping (a polynomial in `ln roughness`).
//!
//! Named metal spectra (`metal-Au-eta`, ...) are reduced to an RGB reflectance at normal
//! incidence (the table below) and given, as pbrt-v4 does for a conductor's `reflectance`, the
//! index `eta = 1`, `k = 2 sqrt(r) / sqrt(1 - r)`, whose normal-incidence Fresnel reflectance is
//! exactly `r`; the angular shape of the real metal's Fresnel curve is approximated.

use englobe::Vec3;

use super::builder::{Builder, MatRef};
use super::params::{Params, Type, Values};
use super::source::{Place, Res, fail};
use super::values::{Role, default_material};
use crate::MaterialModel;
use crate::model::{Material, MaterialId};

/// A black, non-reflecting material with the given parts set afterwards.
fn black() -> Material {
    Material { diffuse: Vec3::ZERO, ..Material::default() }
}

/// Microfacet alpha below which pbrt treats a surface as smooth.
const SMOOTH_ALPHA: f64 = 1e-3;
/// Rough conductors below this alpha are rendered as mirrors, above it as a diffuse colour with
/// a highlight.
const MIRROR_ALPHA: f64 = 0.2;

/// The Blinn-Phong exponent whose lobe matches a Beckmann distribution of roughness `alpha`
/// (Walter et al. 2007, "Microfacet Models for Refraction through Rough Surfaces", eq. 30).
fn phong_exponent(alpha: f64) -> f32 {
    (2.0 / (alpha * alpha) - 2.0).clamp(1.0, 1e4) as f32
}

/// The reflectance at normal incidence of a dielectric of index `eta` in vacuum.
fn dielectric_f0(eta: f64) -> f64 {
    ((eta - 1.0) / (eta + 1.0)).powi(2)
}

/// The reflectance at normal incidence of a conductor of complex index `eta + i k`, per channel.
fn conductor_f0(eta: Vec3, k: Vec3) -> Vec3 {
    let (one, k2) = (Vec3::ONE, k * k);
    ((eta - one) * (eta - one) + k2) / ((eta + one) * (eta + one) + k2)
}

/// Normal-incidence reflectance (linear sRGB) of pbrt-v4's named metals, from the table of
/// Hoffman in Akenine-Möller et al., *Real-Time Rendering*, 4th ed., table 9.2 (MgO and TiO2,
/// dielectrics, from their refractive indices 1.74 and 2.6).
fn named_metal_f0(name: &str) -> Option<Vec3> {
    let metal = name.strip_prefix("metal-")?.rsplit_once('-')?.0;
    Some(match metal {
        "Ag" => Vec3::new(0.97, 0.96, 0.91),
        "Al" => Vec3::new(0.91, 0.92, 0.92),
        "Au" => Vec3::new(1.00, 0.71, 0.29),
        "Cu" => Vec3::new(0.95, 0.64, 0.54),
        "CuZn" => Vec3::new(0.91, 0.78, 0.42),
        "MgO" => Vec3::splat(0.073),
        "TiO2" => Vec3::splat(0.198),
        _ => return None,
    })
}

/// pbrt-v3's roughness remapping (`TrowbridgeReitzDistribution::RoughnessToAlpha` of pbrt-v3).
fn v3_alpha(roughness: f64) -> f64 {
    let x = roughness.max(1e-3).ln();
    1.62142 + 0.819955 * x + 0.1734 * x * x + 0.0171201 * x.powi(3) + 0.000640711 * x.powi(4)
}

/// pbrt-v4's index for a conductor given by its reflectance `r` at normal incidence
/// (`ConductorMaterial`): `eta = 1`, `k = 2 sqrt(r) / sqrt(1 - r)`, whose normal-incidence
/// Fresnel reflectance `k^2 / (4 + k^2)` is `r`. `r` is kept below 0.999 so that `k` is finite.
fn reflectance_index(r: Vec3) -> (Vec3, Vec3) {
    let r = r.clamp(Vec3::ZERO, Vec3::splat(0.999));
    (Vec3::ONE, 2.0 * r.map(f32::sqrt) / (Vec3::ONE - r).map(f32::sqrt))
}

/// The classic material that stands in for a conductor of normal-incidence reflectance `f0` and
/// roughness `alpha` in the Whitted integrator: an untinted mirror when nearly smooth, else a
/// diffuse colour with a Blinn-Phong highlight.
fn classic_conductor(f0: Vec3, alpha: f64) -> Material {
    if alpha < MIRROR_ALPHA {
        Material { reflectivity: (f0.element_sum() / 3.0).min(1.0), ..black() }
    } else {
        Material { diffuse: f0, specular: f0, shininess: phong_exponent(alpha), ..black() }
    }
}

impl Builder {
    /// `Material "type" ...`: the material of the shapes that follow.
    pub fn material(&mut self, at: Place, kind: &str, params: &Params) -> Res<()> {
        self.require_world(at, "Material")?;
        let shown = self.sources.show(at);
        let name = format!("{kind} ({})", shown.rsplit_once(':').map_or(shown.as_str(), |(a, _)| a));
        let id = self.make_material(at, kind, params, name, &format!("Material \"{kind}\""))?;
        self.gs.material = MatRef::Id(id);
        Ok(())
    }

    /// `MakeNamedMaterial "name" "string type" [...] ...`.
    pub fn make_named_material(&mut self, at: Place, name: &str, params: &Params) -> Res<()> {
        self.require_world(at, "MakeNamedMaterial")?;
        let Some((kind, _)) = params.string("type")? else {
            return fail(
                at,
                format!("MakeNamedMaterial \"{name}\" needs its type, as \"string type\" [ \"diffuse\" ]"),
            );
        };
        if self.named_materials.contains_key(name) {
            return fail(at, format!("the named material \"{name}\" is defined twice"));
        }
        let kind = kind.to_owned();
        let what = format!("material \"{name}\" ({kind})");
        let id = self.make_material(at, &kind, params, name.to_owned(), &what)?;
        self.named_materials.insert(name.to_owned(), id);
        Ok(())
    }

    /// `NamedMaterial "name"`: resolved when the file is done.
    pub fn named_material(&mut self, at: Place, name: &str) -> Res<()> {
        self.require_world(at, "NamedMaterial")?;
        self.gs.material = MatRef::Named(name.to_owned(), at);
        Ok(())
    }

    fn make_material(&mut self, at: Place, kind: &str, params: &Params, name: String, what: &str) -> Res<MaterialId> {
        let material = self.classic_material(at, kind, params, what)?;
        for p in ["displacement", "normalmap", "bumpmap"] {
            if let Some(param) = params.touch(p) {
                let shown = param.shown();
                self.report.skipped(param.at, &format!("material {p}"), || {
                    format!("{what}: {shown}: bump, displacement and normal maps are not supported: ignored")
                })?;
            }
        }
        self.report_unused(params, &format!("Material {kind}"), what)?;
        Ok(match material {
            Some(m) => self.add_material(name, m, false),
            None => self.add_material(name, default_material(), true),
        })
    }

    /// The microfacet alpha of a material's roughness parameters (the mean of its two axes).
    fn alpha(&mut self, params: &Params, what: &str, prefix: &str, default: f64, v3: bool) -> Res<f64> {
        let r = self.scalar(params, &format!("{prefix}roughness"), what)?.unwrap_or(default);
        let u = self.scalar(params, &format!("{prefix}uroughness"), what)?.unwrap_or(r);
        let v = self.scalar(params, &format!("{prefix}vroughness"), what)?.unwrap_or(r);
        let remap = params.bool("remaproughness")?.unwrap_or(true);
        let to_alpha = |x: f64| {
            let x = x.max(0.0);
            match (remap, v3) {
                (false, _) => x,
                (true, false) => x.sqrt(),
                (true, true) => v3_alpha(x),
            }
        };
        let (au, av) = (to_alpha(u), to_alpha(v));
        if (au - av).abs() > 1e-6 {
            let at = params
                .at_or(&format!("{prefix}uroughness"), params.at_or(&format!("{prefix}vroughness"), Place::START));
            let mean = 0.5 * (au + av);
            self.report.approximated(at, &format!("anisotropic {what} {au} {av}"), || {
                format!("{what}: anisotropic roughness (alpha {au:.3} along u, {av:.3} along v) is rendered isotropic, alpha {mean:.3}")
            })?;
        }
        Ok(0.5 * (au + av))
    }

    /// A refractive index: a float, or a spectrum at 550 nm.
    fn eta(&mut self, params: &Params, name: &str, what: &str) -> Res<f64> {
        let eta = self.scalar(params, name, what)?.unwrap_or(1.5);
        if !(eta > 0.0) {
            return fail(params.at_or(name, Place::START), format!("{what}: {name} must be positive, found {eta}"));
        }
        Ok(eta)
    }

    /// A conductor's complex index `(eta, k)` per channel: from its `reflectance` (through
    /// [`reflectance_index`], as pbrt-v4 does), or its `eta` and `k` (named pbrt spectra through
    /// [`named_metal_f0`]); copper by default, as in pbrt.
    fn metal_index(&mut self, params: &Params, prefix: &str, what: &str) -> Res<(Vec3, Vec3)> {
        let copper = || reflectance_index(named_metal_f0("metal-Cu-eta").expect("copper is in the table"));
        if let Some(r) = self.color(params, &format!("{prefix}reflectance"), Role::Reflectance, what)? {
            return Ok(reflectance_index(r));
        }
        let (eta_name, k_name) = (format!("{prefix}eta"), format!("{prefix}k"));
        let named = |p: Option<&super::params::Param>| match p.map(|p| &p.values) {
            Some(Values::Strings(s)) => Some(s[0].clone()),
            _ => None,
        };
        let eta_spectrum = params.get(&eta_name, &[Type::Rgb, Type::Spectrum, Type::Float])?;
        if eta_spectrum.is_none() && !params.has(&k_name) {
            return Ok(copper());
        }
        if let Some(name) = named(eta_spectrum) {
            params.touch(&k_name);
            return match named_metal_f0(&name) {
                Some(f0) => {
                    let at = eta_spectrum.map_or(Place::START, |p| p.at);
                    self.report.approximated(at, &format!("metal {name} {what}"), || {
                        format!(
                            "{what}: the spectrum \"{name}\" is rendered as its RGB reflectance at normal incidence \
                             {f0} (the angular shape of its Fresnel curve is approximated)"
                        )
                    })?;
                    Ok(reflectance_index(f0))
                }
                None => {
                    let at = eta_spectrum.map_or(Place::START, |p| p.at);
                    self.report.skipped(at, &format!("metal {name}"), || {
                        format!("{what}: the spectrum \"{name}\" is not known: copper is used")
                    })?;
                    Ok(copper())
                }
            };
        }
        let eta = match eta_spectrum.map(|p| (p.ty, &p.values)) {
            Some((Type::Float, Values::Numbers(v))) => Vec3::splat(v[0] as f32),
            _ => self.color(params, &eta_name, Role::Unbounded, what)?.unwrap_or(Vec3::splat(0.2)),
        };
        let k = self.color(params, &k_name, Role::Unbounded, what)?.unwrap_or(Vec3::splat(3.9));
        Ok((eta.max(Vec3::splat(1e-3)), k.max(Vec3::ZERO)))
    }

    /// The englobe material nearest to pbrt material `kind` with `params`; `None` for pbrt's
    /// `interface` (a boundary of media only: its shapes are not drawn). Reports what is
    /// approximated, naming `what` (the material) at `at`.
    pub fn classic_material(&mut self, at: Place, kind: &str, params: &Params, what: &str) -> Res<Option<Material>> {
        // Keyed by the message, which holds the material's values: two materials approximated
        // alike are one report, two different ones two.
        let approx = |b: &mut Builder, key: &str, message: String| {
            b.report.approximated(at, &format!("{key} {message}"), || message)
        };
        let m = match kind {
            "diffuse" => {
                let reflectance = self.color(params, "reflectance", Role::Reflectance, what)?;
                Material { diffuse: reflectance.unwrap_or(Vec3::splat(0.5)), ..black() }
            }
            "matte" => {
                let kd = self.color(params, "Kd", Role::Reflectance, what)?.unwrap_or(Vec3::splat(0.5));
                if self.scalar(params, "sigma", what)?.unwrap_or(0.0) != 0.0 {
                    approx(
                        self,
                        "oren-nayar",
                        format!("{what}: Oren-Nayar roughness (sigma) is rendered as Lambertian"),
                    )?;
                }
                Material { diffuse: kd, ..black() }
            }
            "dielectric" | "glass" => {
                let eta =
                    if params.has("index") { self.eta(params, "index", what)? } else { self.eta(params, "eta", what)? };
                let alpha = self.alpha(params, what, "", 0.0, kind == "glass")?;
                if kind == "glass" {
                    let kr = self.color(params, "Kr", Role::Reflectance, what)?.unwrap_or(Vec3::ONE);
                    let kt = self.color(params, "Kt", Role::Reflectance, what)?.unwrap_or(Vec3::ONE);
                    if kr != Vec3::ONE || kt != Vec3::ONE {
                        approx(self, "glass tint", format!("{what}: Kr {kr} and Kt {kt} are rendered as 1"))?;
                    }
                }
                // The classic fields: Whitted's smooth glass.
                Material {
                    transparency: 1.0,
                    ior: eta as f32,
                    model: MaterialModel::Dielectric { alpha: alpha as f32 },
                    ..black()
                }
            }
            "thindielectric" => {
                let eta = self.eta(params, "eta", what)?;
                let f0 = dielectric_f0(eta);
                // A thin slab at normal incidence, with the reflections inside it summed.
                let r = (2.0 * f0 / (1.0 + f0)) as f32;
                approx(
                    self,
                    "thin dielectric",
                    format!(
                        "{what}: a thin dielectric of index {eta} is rendered as reflecting {r:.4} and transmitting the \
                     rest straight through, at every angle"
                    ),
                )?;
                Material { reflectivity: r, transparency: 1.0 - r, ior: 1.0, ..black() }
            }
            "conductor" | "metal" | "coatedconductor" | "mirror" => {
                let prefix = if kind == "coatedconductor" { "conductor." } else { "" };
                let (eta, k, alpha) = if kind == "mirror" {
                    // pbrt-v3's mirror: a smooth conductor reflecting Kr at every angle but
                    // grazing ones (pbrt-v3 used a constant Fresnel of Kr).
                    let kr = self.color(params, "Kr", Role::Reflectance, what)?.unwrap_or(Vec3::splat(0.9));
                    let (eta, k) = reflectance_index(kr);
                    (eta, k, 0.0)
                } else {
                    let (eta, k) = self.metal_index(params, prefix, what)?;
                    let default_roughness = if kind == "metal" { 0.01 } else { 0.0 };
                    (eta, k, self.alpha(params, what, prefix, default_roughness, kind == "metal")?)
                };
                if kind == "coatedconductor" {
                    for p in [
                        "interface.eta",
                        "interface.roughness",
                        "interface.uroughness",
                        "interface.vroughness",
                        "thickness",
                        "albedo",
                        "g",
                        "maxdepth",
                        "nsamples",
                    ] {
                        params.touch(p);
                    }
                    approx(
                        self,
                        "conductor coat",
                        format!(
                            "{what}: the dielectric coat of a coated conductor is left out: rendered as the bare conductor"
                        ),
                    )?;
                }
                let mut m = classic_conductor(conductor_f0(eta, k), alpha);
                m.model = MaterialModel::Conductor { eta, k, alpha: alpha as f32 };
                m
            }
            "coateddiffuse" => {
                let base = self.color(params, "reflectance", Role::Reflectance, what)?.unwrap_or(Vec3::splat(0.5));
                let eta = self.eta(params, "eta", what)?;
                let alpha = self.alpha(params, what, "", 0.0, false)?;
                for p in ["thickness", "g", "maxdepth", "nsamples"] {
                    params.touch(p);
                }
                if self.color(params, "albedo", Role::Reflectance, what)?.is_some_and(|a| a != Vec3::ZERO) {
                    approx(self, "coat albedo", format!("{what}: the medium inside the coat (albedo) is left out"))?;
                }
                approx(
                    self,
                    "coated diffuse",
                    format!(
                        "{what}: pbrt's layered coateddiffuse is rendered as a Lambertian base {base} under a GGX coat \
                         of index {eta} and alpha {alpha:.3} coupled by albedo scaling (Schlick's Fresnel; the base \
                         does not darken through bounces inside the coat)"
                    ),
                )?;
                // The classic fields: the base under a fixed mirror share (Whitted).
                let reflectivity = dielectric_f0(eta) as f32;
                Material {
                    diffuse: base,
                    reflectivity: reflectivity.min(1.0),
                    ior: eta as f32,
                    model: MaterialModel::CoatedDiffuse { alpha: alpha as f32 },
                    ..black()
                }
            }
            "plastic" | "substrate" => {
                let (base, spec, alpha) = match kind {
                    "plastic" => {
                        let kd = self.color(params, "Kd", Role::Reflectance, what)?.unwrap_or(Vec3::splat(0.25));
                        let ks = self.color(params, "Ks", Role::Reflectance, what)?.unwrap_or(Vec3::splat(0.25));
                        (kd, ks, self.alpha(params, what, "", 0.1, true)?)
                    }
                    _ => {
                        let kd = self.color(params, "Kd", Role::Reflectance, what)?.unwrap_or(Vec3::splat(0.5));
                        let ks = self.color(params, "Ks", Role::Reflectance, what)?.unwrap_or(Vec3::splat(0.5));
                        (kd, ks, self.alpha(params, what, "", 0.1, true)?)
                    }
                };
                if alpha < SMOOTH_ALPHA {
                    let reflectivity = spec.element_sum() / 3.0;
                    approx(
                        self,
                        "smooth coat",
                        format!(
                            "{what}: a smooth coat over a diffuse base is rendered as the base {base} under a fixed \
                         mirror reflection of {reflectivity:.3} (the coat's reflectance at normal incidence: no \
                         angular Fresnel, no inter-reflection inside the coat)"
                        ),
                    )?;
                    Material { diffuse: base, reflectivity: reflectivity.min(1.0), ..black() }
                } else {
                    approx(
                        self,
                        "rough coat",
                        format!(
                            "{what}: a rough coat (alpha {alpha:.3}) over a diffuse base is rendered as the base {base} \
                         with a Blinn-Phong highlight {spec} from point and distant lights"
                        ),
                    )?;
                    Material { diffuse: base, specular: spec, shininess: phong_exponent(alpha), ..black() }
                }
            }
            "diffusetransmission" | "translucent" => {
                let name = if kind == "translucent" { "Kd" } else { "reflectance" };
                let r = self.color(params, name, Role::Reflectance, what)?.unwrap_or(Vec3::splat(0.25));
                for p in ["transmittance", "Ks", "reflect", "transmit", "roughness", "scale"] {
                    params.touch(p);
                }
                approx(
                    self,
                    "transmission",
                    format!("{what}: rendered as Lambertian {r}: its diffuse transmission is left out"),
                )?;
                Material { diffuse: r, ..black() }
            }
            "interface" | "" | "none" => {
                self.report.ignored(at, "interface", || {
                    format!("{what}: shapes with an interface material only bound media, which englobe does not render: they are not drawn")
                })?;
                return Ok(None);
            }
            _ => {
                for p in params.unused().map(|p| p.name.clone()).collect::<Vec<_>>() {
                    params.touch(&p);
                }
                self.report.skipped(at, &format!("material type {kind}"), || {
                    format!(
                        "{what}: materials of type \"{kind}\" are not supported: pbrt's default (diffuse 0.5) is used"
                    )
                })?;
                default_material()
            }
        };
        Ok(Some(m))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_forms() {
        assert!((dielectric_f0(1.5) - 0.04).abs() < 1e-12);
        // A conductor with k = 0 is a dielectric.
        assert!((conductor_f0(Vec3::splat(1.5), Vec3::ZERO) - Vec3::splat(0.04)).abs().max_element() < 1e-6);
        // eta = 2, k = 3: ((2 - 1)^2 + 9) / ((2 + 1)^2 + 9) = 10 / 18.
        assert!((conductor_f0(Vec3::splat(2.0), Vec3::splat(3.0)).y - 10.0 / 18.0).abs() < 1e-6);
        assert_eq!(named_metal_f0("metal-Au-eta"), named_metal_f0("metal-Au-k"));
        assert!(named_metal_f0("metal-Unobtainium-eta").is_none() && named_metal_f0("glass-BK7").is_none());
        // alpha = 0.5 is a Phong exponent of 6; alpha = 1 of the minimum, 1 (clamped from 0).
        assert_eq!(phong_exponent(0.5), 6.0);
        assert_eq!(phong_exponent(1.0), 1.0);
        // pbrt-v3 maps roughness 0.01 (its metal's default) to alpha ~0.138.
        assert!((v3_alpha(0.01) - 0.138).abs() < 0.002);
    }
}
