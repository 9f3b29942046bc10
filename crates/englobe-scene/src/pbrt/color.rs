//! Colour and number parameters as englobe reads them: `rgb` values as they are (linear sRGB, as
//! pbrt-v4 renders them), `blackbody` and `spectrum` values through [`super::spectrum`], and
//! `texture` values through the constant textures of [`super::textures`]. What cannot be read
//! exactly is reported at the parameter.

use englobe::Vec3;
use glam::DVec3;

use super::builder::Builder;
use super::params::{Param, Params, Type, Values};
use super::source::{Res, fail};
use super::spectrum::{blackbody_rgb, sampled_rgb};
use super::values::{Role, TexValue};

/// Linear sRGB of a named spectrum, where englobe knows it: the sRGB white (D65) and CIE
/// illuminant A (a black body at 2856 K by definition) as lights.
fn named_light(name: &str) -> Option<DVec3> {
    match name {
        "stdillum-D65" => Some(DVec3::ONE),
        "stdillum-A" => blackbody_rgb(2856.0),
        _ => None,
    }
}

fn to_vec3(c: DVec3) -> Vec3 {
    c.as_vec3()
}

impl Builder {
    /// The colour of parameter `name` (any of `rgb`, `spectrum`, `blackbody`, `texture`), for
    /// `what` (the directive, for messages).
    pub fn color(&mut self, params: &Params, name: &str, role: Role, what: &str) -> Res<Option<Vec3>> {
        let types = [Type::Rgb, Type::Spectrum, Type::Blackbody, Type::Texture];
        let Some(p) = params.get(name, &types)? else { return Ok(None) };
        let c = match (p.ty, &p.values) {
            (Type::Rgb, Values::Numbers(v)) => {
                if v.len() != 3 {
                    return fail(p.at, format!("parameter {} takes one RGB colour (3 numbers)", p.shown()));
                }
                let c = DVec3::new(v[0], v[1], v[2]);
                if c.min_element() < 0.0 {
                    return fail(p.at, format!("parameter {}: a colour cannot be negative, found {c}", p.shown()));
                }
                c
            }
            (Type::Blackbody, Values::Numbers(v)) => self.blackbody(p, v, what)?,
            (Type::Spectrum, Values::Numbers(v)) => {
                let Some(mut c) = sampled_rgb(v) else {
                    return fail(p.at, format!("parameter {}: the wavelengths must increase", p.shown()));
                };
                if role == Role::Light {
                    c /= luminance(c).max(1e-12);
                }
                self.report.approximated(p.at, &format!("spectrum {what} {name}"), || {
                    format!("{what}: the sampled spectrum {} is rendered as the RGB colour {c}", p.shown())
                })?;
                c.max(DVec3::ZERO)
            }
            (Type::Spectrum, Values::Strings(s)) => {
                let named = if role == Role::Light { named_light(&s[0]) } else { None };
                match named {
                    Some(c) => c,
                    None => {
                        self.report.skipped(p.at, &format!("named spectrum {}", s[0]), || {
                            format!("{what}: the named spectrum \"{}\" is not known: pbrt's default is used", s[0])
                        })?;
                        return Ok(None);
                    }
                }
            }
            (Type::Texture, Values::Strings(s)) => match self.texture_value(p, &s[0], false, what)? {
                Some(TexValue::Color(c)) => c.as_dvec3(),
                Some(TexValue::Float(f)) => DVec3::splat(f),
                None => return Ok(None),
            },
            _ => return fail(p.at, format!("parameter {} has no colour value", p.shown())),
        };
        if role == Role::Reflectance && c.max_element() > 1.0 {
            let clamped = c.min(DVec3::ONE);
            self.report.approximated(p.at, &format!("reflectance above 1 {what} {name}"), || {
                format!("{what}: parameter {} is {c}, above 1: clamped to {clamped}", p.shown())
            })?;
            return Ok(Some(to_vec3(clamped)));
        }
        Ok(Some(to_vec3(c)))
    }

    /// The number of parameter `name`: a `float`, or a `texture` naming a constant float texture.
    pub fn scalar(&mut self, params: &Params, name: &str, what: &str) -> Res<Option<f64>> {
        let Some(p) = params.get(name, &[Type::Float, Type::Texture, Type::Spectrum])? else { return Ok(None) };
        match (&p.ty, &p.values) {
            (Type::Float, Values::Numbers(v)) if v.len() == 1 => Ok(Some(v[0])),
            (Type::Float, _) => fail(p.at, format!("parameter {} takes one value", p.shown())),
            (Type::Texture, Values::Strings(s)) => Ok(match self.texture_value(p, &s[0], true, what)? {
                Some(TexValue::Float(f)) => Some(f),
                Some(TexValue::Color(c)) => Some(c.element_sum() as f64 / 3.0),
                None => None,
            }),
            (Type::Spectrum, values) => {
                // pbrt accepts spectra for some numbers (a dispersive `eta`); englobe takes the
                // value at 550 nm, the middle of the visible range.
                let value = match values {
                    Values::Numbers(v) => sample_at(v, 550.0),
                    Values::Strings(s) => named_glass_eta(&s[0]),
                    Values::Bools(_) => None,
                };
                let Some(value) = value else {
                    self.report.skipped(p.at, &format!("spectrum {what} {name}"), || {
                        format!(
                            "{what}: parameter {} is not a spectrum englobe knows: pbrt's default is used",
                            p.shown()
                        )
                    })?;
                    return Ok(None);
                };
                self.report.approximated(p.at, &format!("dispersion {what} {name}"), || {
                    format!("{what}: the spectrum {} is rendered with its value at 550 nm, {value}", p.shown())
                })?;
                Ok(Some(value))
            }
            _ => fail(p.at, format!("parameter {} has no numeric value", p.shown())),
        }
    }

    fn blackbody(&mut self, p: &Param, v: &[f64], what: &str) -> Res<DVec3> {
        let (kelvin, factor) = match v {
            [t] => (*t, 1.0),
            // pbrt-v3 wrote a temperature and a scale.
            [t, s] => {
                self.report.approximated(p.at, "blackbody v3", || {
                    format!("{what}: pbrt-v3's blackbody (temperature, scale) is read as pbrt-v4's, times the scale")
                })?;
                (*t, *s)
            }
            _ => return fail(p.at, format!("parameter {} takes one temperature in kelvin", p.shown())),
        };
        match blackbody_rgb(kelvin) {
            Some(c) => Ok(c * factor.max(0.0)),
            None => fail(p.at, format!("parameter {}: a temperature must be positive, found {kelvin}", p.shown())),
        }
    }
}

/// Rec. 709 luminance of linear sRGB.
pub(super) fn luminance(c: DVec3) -> f64 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// The value of `(wavelength, value)` pairs at `lambda`, linearly interpolated.
fn sample_at(pairs: &[f64], lambda: f64) -> Option<f64> {
    let n = pairs.len() / 2;
    if n == 0 {
        return None;
    }
    let i = (0..n).position(|i| pairs[2 * i] >= lambda).unwrap_or(n);
    Some(match i {
        0 => pairs[1],
        i if i == n => pairs[2 * n - 1],
        i => {
            let (l0, v0, l1, v1) = (pairs[2 * i - 2], pairs[2 * i - 1], pairs[2 * i], pairs[2 * i + 1]);
            if l1 > l0 { v0 + (v1 - v0) * (lambda - l0) / (l1 - l0) } else { v1 }
        }
    })
}

/// The refractive index near 550 nm of pbrt-v4's named glasses (Schott's catalogue, n_d).
fn named_glass_eta(name: &str) -> Option<f64> {
    Some(match name {
        "glass-BK7" => 1.5168,
        "glass-BAF10" => 1.6700,
        "glass-FK51A" => 1.4866,
        "glass-LASF9" => 1.8503,
        _ => return None,
    })
}
