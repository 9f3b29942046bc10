//! `Texture "name" "spectrum"|"float" "class" ...`: englobe's materials are constant, so a texture
//! is read only when it has one value: `constant`, and `scale` and `mix` of constants (exactly);
//! `checkerboard` as the mean of its two values (approximated). Other classes (`imagemap`,
//! noise, ...) are reported, and materials that use them get pbrt's default for the parameter.
//! As in pbrt-v4, float and spectrum textures have names of their own.

use englobe::Vec3;

use super::builder::Builder;
use super::params::{Param, Params};
use super::source::{Place, Res, fail};
use super::values::{Role, TexValue, Texture, key};

impl Builder {
    /// The `Texture` directive.
    pub fn texture(&mut self, at: Place, name: &str, ty: &str, class: &str, params: &Params) -> Res<()> {
        self.require_world(at, "Texture")?;
        let float = match ty {
            "float" => true,
            "spectrum" | "color" | "rgb" => false,
            _ => {
                return fail(
                    at,
                    format!("Texture \"{name}\": unknown type \"{ty}\": expected \"float\" or \"spectrum\""),
                );
            }
        };
        let what = format!("Texture \"{name}\"");
        let value = |b: &mut Builder, p: &str, default: f64| -> Res<Option<TexValue>> {
            Ok(if float {
                b.scalar(params, p, &what)?.or(Some(default)).map(TexValue::Float)
            } else {
                b.color(params, p, Role::Unbounded, &what)?.or(Some(Vec3::splat(default as f32))).map(TexValue::Color)
            })
        };
        let value = match class {
            "constant" => value(self, "value", 1.0)?,
            "scale" => match (value(self, "tex", 1.0)?, self.scalar(params, "scale", &what)?.unwrap_or(1.0)) {
                (Some(TexValue::Float(f)), s) => Some(TexValue::Float(f * s)),
                (Some(TexValue::Color(c)), s) => Some(TexValue::Color(c * s as f32)),
                (None, _) => None,
            },
            "mix" => {
                let amount = self.scalar(params, "amount", &what)?.unwrap_or(0.5);
                match (value(self, "tex1", 0.0)?, value(self, "tex2", 1.0)?) {
                    (Some(TexValue::Float(a)), Some(TexValue::Float(b))) => Some(TexValue::Float(a + (b - a) * amount)),
                    (Some(TexValue::Color(a)), Some(TexValue::Color(b))) => {
                        Some(TexValue::Color(a.lerp(b, amount as f32)))
                    }
                    _ => None,
                }
            }
            "checkerboard" => {
                let mean = match (value(self, "tex1", 1.0)?, value(self, "tex2", 0.0)?) {
                    (Some(TexValue::Float(a)), Some(TexValue::Float(b))) => Some(TexValue::Float((a + b) / 2.0)),
                    (Some(TexValue::Color(a)), Some(TexValue::Color(b))) => Some(TexValue::Color((a + b) / 2.0)),
                    _ => None,
                };
                for p in ["dimension", "mapping", "uscale", "vscale", "udelta", "vdelta"] {
                    params.touch(p);
                }
                self.report.approximated(at, &format!("checkerboard {name}"), || {
                    format!("{what}: a checkerboard is rendered as the mean of its two values")
                })?;
                mean
            }
            _ => {
                for p in params.unused().map(|p| p.name.clone()).collect::<Vec<_>>() {
                    params.touch(&p);
                }
                self.report.skipped(at, &format!("texture class {class}"), || {
                    format!(
                        "{what}: textures of class \"{class}\" are not supported: materials using it get pbrt's \
                         default value"
                    )
                })?;
                None
            }
        };
        self.report_unused(params, &format!("Texture {class}"), &what)?;
        self.textures.insert(key(name, float), Texture { value, class: class.to_owned() });
        Ok(())
    }

    /// The value of the texture named by parameter `p`, or `None` (reported) when it has none; an
    /// undefined texture is an error, as in pbrt.
    pub fn texture_value(&mut self, p: &Param, name: &str, float: bool, what: &str) -> Res<Option<TexValue>> {
        let Some(t) = self.textures.get(&key(name, float)) else {
            let kind = if float { "float" } else { "spectrum" };
            return fail(p.at, format!("{what}: parameter {} names no {kind} texture \"{name}\"", p.shown()));
        };
        if t.value.is_none() {
            let class = t.class.clone();
            self.report.skipped(p.at, &format!("texture use {name}"), || {
                format!(
                    "{what}: parameter {} uses the \"{class}\" texture \"{name}\", which englobe cannot read: \
                     pbrt's default value is used",
                    p.shown()
                )
            })?;
        }
        Ok(self.textures.get(&key(name, float)).and_then(|t| t.value))
    }
}
