//! `LightSource` and `AreaLightSource`, with pbrt-v4's units converted to englobe's.
//!
//! pbrt-v4 (`lights.cpp`): a point light's `I` is a radiant intensity, a distant light's `L` the
//! radiance of a source subtending a delta solid angle (so it delivers irradiance `L cos`), an
//! area light's `L` and an infinite light's `L` radiances; each is multiplied by `scale`, and by
//! `power` or `illuminance` over the light's own normalisation when those are given.
//!
//! englobe's point and directional lights are in the classic units of its shading (see
//! `englobe-render`'s `shading.rs`): a diffuse surface of colour `rho` facing a point light of
//! `power` `P` at distance `d` reflects `rho P / d²`, with no `1 / pi`, where physics gives
//! `rho / pi * I / d²`; so `P = I / pi`, and a directional light's radiance is pbrt's `L / pi`.
//! Emissive surfaces and the background are radiances in both renderers and keep their values.

use englobe::Vec3;
use glam::DVec3;

use super::builder::{AreaLight, Builder};
use super::params::Params;
use super::source::{Place, Res, fail};
use super::values::Role;
use crate::model::Light;

const PI: f64 = std::f64::consts::PI;

impl Builder {
    /// The spectrum parameter `name` of a light, scaled by `scale`: pbrt's default spectrum is
    /// the colour space's illuminant, which is white (1, 1, 1) in englobe's linear sRGB.
    fn light_color(&mut self, params: &Params, name: &str, what: &str) -> Res<Vec3> {
        let c = self.color(params, name, Role::Light, what)?.unwrap_or(Vec3::ONE);
        let scale = params.float("scale")?.unwrap_or(1.0);
        if !(scale >= 0.0) {
            return fail(params.at_or("scale", Place::START), format!("{what}: the scale cannot be negative"));
        }
        Ok(c * scale as f32)
    }

    /// The `LightSource` directive.
    pub fn light_source(&mut self, at: Place, kind: &str, params: &Params) -> Res<()> {
        self.require_world(at, "LightSource")?;
        let what = format!("LightSource \"{kind}\"");
        let ctm = self.gs.ctm;
        match kind {
            "point" => {
                let mut intensity = self.light_color(params, "I", &what)?;
                if let Some(power) = params.float("power")?.filter(|&p| p > 0.0) {
                    intensity *= (power / (4.0 * PI)) as f32;
                }
                let from = point(params, "from", DVec3::ZERO)?;
                let position = ctm.transform_point3(from).as_vec3();
                self.check_finite(at, position, &what)?;
                self.lights.push(Light::Point { position, power: intensity / std::f32::consts::PI });
            }
            "distant" => {
                let mut radiance = self.light_color(params, "L", &what)?;
                if let Some(e) = params.float("illuminance")?.filter(|&e| e > 0.0) {
                    radiance *= e as f32;
                }
                let from = point(params, "from", DVec3::ZERO)?;
                let to = point(params, "to", DVec3::Z)?;
                let Some(direction) = ctm.transform_vector3(to - from).try_normalize() else {
                    return fail(at, format!("{what}: \"from\" and \"to\" must differ"));
                };
                self.lights.push(Light::Directional {
                    direction: direction.as_vec3(),
                    radiance: radiance / std::f32::consts::PI,
                });
            }
            "infinite" => {
                if let Some((file, file_at)) = params.string("filename")? {
                    let file = file.to_owned();
                    params.touch("L");
                    params.touch("scale");
                    params.touch("illuminance");
                    params.touch("portal");
                    return self.report.skipped(file_at, "environment map", || {
                        format!("{what}: environment maps (\"{file}\") are not supported yet: the light is left out")
                    });
                }
                let mut radiance = self.light_color(params, "L", &what)?;
                if let Some(e) = params.float("illuminance")?.filter(|&e| e > 0.0) {
                    // A uniform sky of radiance L gives an upward surface the illuminance pi L.
                    radiance *= (e / PI) as f32;
                }
                if let Some(p) = params.touch("portal") {
                    let portal_at = p.at;
                    self.report
                        .ignored(portal_at, "portal", || format!("{what}: portals only guide sampling: ignored"))?;
                }
                self.background += radiance;
            }
            _ => {
                for p in params.unused().map(|p| p.name.clone()).collect::<Vec<_>>() {
                    params.touch(&p);
                }
                return self.report.skipped(at, &format!("light {kind}"), || {
                    format!("{what}: lights of this type are not supported: the light is left out")
                });
            }
        }
        self.report_unused(params, &format!("LightSource {kind}"), &what)
    }

    /// The `AreaLightSource` directive: the shapes that follow in the same attribute scope emit.
    pub fn area_light_source(&mut self, at: Place, kind: &str, params: &Params) -> Res<()> {
        self.require_world(at, "AreaLightSource")?;
        let what = format!("AreaLightSource \"{kind}\"");
        if kind != "diffuse" && kind != "area" {
            for p in params.unused().map(|p| p.name.clone()).collect::<Vec<_>>() {
                params.touch(&p);
            }
            self.gs.area_light = None;
            return self.report.skipped(at, &format!("area light {kind}"), || {
                format!("{what}: area lights of this type are not supported: the shapes do not emit")
            });
        }
        let radiance = self.light_color(params, "L", &what)?;
        let two_sided = params.bool("twosided")?.unwrap_or(false);
        if two_sided {
            self.report.approximated(at, "two-sided", || {
                format!("{what}: two-sided emission is not supported: the shapes emit from their front side only")
            })?;
        }
        if let Some(p) = params.touch("filename") {
            let file_at = p.at;
            self.report.skipped(file_at, "area light image", || {
                format!("{what}: emission images are not supported: L is used")
            })?;
        }
        if let Some(p) = params.touch("nsamples") {
            let n_at = p.at;
            self.report
                .ignored(n_at, "nsamples", || format!("{what}: pbrt-v3's nsamples only changes noise: ignored"))?;
        }
        let power = params.float("power")?.filter(|&p| p > 0.0);
        self.report_unused(params, &format!("AreaLightSource {kind}"), &what)?;
        self.gs.area_light = Some(AreaLight { radiance, power, two_sided, at });
        Ok(())
    }

    fn check_finite(&self, at: Place, p: Vec3, what: &str) -> Res<()> {
        if !p.is_finite() {
            return fail(at, format!("{what}: the light lies beyond the range of 32-bit floats"));
        }
        Ok(())
    }
}

/// The point parameter `name` (`from`, `to`), or `default`.
fn point(params: &Params, name: &str, default: DVec3) -> Res<DVec3> {
    use super::params::Type;
    match params.numbers(name, &[Type::Point3])? {
        Some((v, _)) if v.len() == 3 => Ok(DVec3::new(v[0], v[1], v[2])),
        Some((_, at)) => fail(at, format!("parameter \"point3 {name}\" takes one point")),
        None => Ok(default),
    }
}
