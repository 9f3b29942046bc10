//! `[materials.NAME]` tables: the classic keys of the seed and the metallic-roughness ones
//! (documented in `docs/scene-format.md`), checked together (keys of one model refused under
//! the other), with their texture files decoded once per scene. A texture file that cannot be
//! read is a warning and the material's fallback, not an error: the scene still renders.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use toml::Spanned;

use crate::error::SceneError;
use crate::format::{AlphaModeKind, MaterialDef, MaterialModelKind, WrapKind};
use crate::material::{Alpha, AlphaMode, Material, MaterialModel, NormalEncoding, NormalMap, TextureRef};
use crate::parse::{Converter, DEFAULT_MATERIAL};
use crate::texture::{Sampler, Texture, TextureId, TextureLoader, TextureSource, Wrap};

/// The scene's materials, their names and the textures they use.
pub(crate) type Materials = (Vec<Material>, Vec<String>, Vec<Arc<Texture>>);

impl Converter<'_> {
    pub(crate) fn materials(
        &self,
        defs: BTreeMap<String, Spanned<MaterialDef>>,
        warnings: &mut Vec<String>,
    ) -> Result<Materials, SceneError> {
        let mut materials = vec![Material::default()];
        let mut names = vec![DEFAULT_MATERIAL.to_owned()];
        let mut textures = Vec::new();
        let mut loader = TextureLoader::default();
        for (name, def) in defs {
            let span = def.span();
            let d = def.into_inner();
            let m = self.material(&name, span, d, &mut textures, &mut loader, warnings)?;
            if name == DEFAULT_MATERIAL {
                materials[0] = m;
            } else {
                materials.push(m);
                names.push(name);
            }
        }
        Ok((materials, names, textures))
    }

    fn material(
        &self,
        name: &str,
        span: std::ops::Range<usize>,
        d: MaterialDef,
        textures: &mut Vec<Arc<Texture>>,
        loader: &mut TextureLoader,
        warnings: &mut Vec<String>,
    ) -> Result<Material, SceneError> {
        let base = Material::default();
        let model = d.model.unwrap_or_default();
        let is_mr = model == MaterialModelKind::MetallicRoughness;
        let only_mr = [
            ("metallic", d.metallic.as_ref()),
            ("roughness", d.roughness.as_ref()),
            ("transmission", d.transmission.as_ref()),
        ];
        for (key, value) in only_mr {
            if let (Some(v), false) = (value, is_mr) {
                return Err(self.err(
                    v.span(),
                    format!("material `{name}`: `{key}` belongs to `model = \"metallic_roughness\"`, which this material does not set"),
                ));
            }
        }
        let diffuse = match (&d.diffuse, &d.base_color) {
            (Some(_), Some(b)) => {
                return Err(self.err(
                    b.span(),
                    format!("material `{name}`: `base_color` and `diffuse` are the same colour; give one"),
                ));
            }
            (Some(c), None) | (None, Some(c)) => c.get_ref().0,
            (None, None) => base.diffuse,
        };
        let mut m = Material {
            diffuse,
            specular: d.specular.map_or(base.specular, |c| c.0),
            shininess: d.shininess.map_or(base.shininess, |x| x.0),
            reflectivity: d.reflectivity.map_or(base.reflectivity, |x| x.0),
            transparency: d.transparency.map_or(base.transparency, |x| x.0),
            ior: d.ior.map_or(base.ior, |x| x.0),
            emission: d.emission.map_or(base.emission, |c| c.0) * d.emission_strength.map_or(1.0, |s| s.0),
            double_sided: d.double_sided.unwrap_or(true),
            ..base
        };
        if is_mr {
            m.model = MaterialModel::MetallicRoughness {
                metallic: d.metallic.map_or(1.0, |v| v.get_ref().0),
                roughness: d.roughness.map_or(1.0, |v| v.get_ref().0),
                transmission: d.transmission.map_or(0.0, |v| v.get_ref().0),
            };
        }
        if m.reflectivity + m.transparency > 1.0 {
            return Err(self.err(
                span,
                format!(
                    "material `{name}`: reflectivity + transparency is {}, expected at most 1",
                    m.reflectivity + m.transparency
                ),
            ));
        }
        let mode = match (d.alpha_mode.unwrap_or_default(), &d.alpha_cutoff) {
            (AlphaModeKind::Mask, cutoff) => AlphaMode::Mask { cutoff: cutoff.as_ref().map_or(0.5, |c| c.get_ref().0) },
            (_, Some(c)) => {
                return Err(
                    self.err(c.span(), format!("material `{name}`: `alpha_cutoff` needs `alpha_mode = \"mask\"`"))
                );
            }
            (AlphaModeKind::Opaque, None) => AlphaMode::Opaque,
            (AlphaModeKind::Blend, None) => AlphaMode::Blend,
        };
        m.alpha = Alpha { mode, factor: d.alpha.map_or(1.0, |a| a.0) };

        let wrap = match d.texture_wrap.unwrap_or_default() {
            WrapKind::Repeat => Wrap::Repeat,
            WrapKind::MirroredRepeat => Wrap::MirroredRepeat,
            WrapKind::ClampToEdge => Wrap::ClampToEdge,
        };
        let mut texture = |slot: &str, file: &Option<Spanned<String>>| -> Option<TextureRef> {
            let file = file.as_ref()?;
            let id = self.texture(name, slot, file.get_ref(), Sampler::wrapping(wrap), textures, loader, warnings);
            Some(TextureRef::new(id))
        };
        m.textures.base_color = texture("base colour", &d.base_color_texture);
        m.textures.metallic_roughness = texture("metallic-roughness", &d.metallic_roughness_texture);
        m.textures.emission = texture("emission", &d.emission_texture);
        m.textures.normal = texture("normal", &d.normal_texture).map(|t| NormalMap {
            texture: t,
            scale: d.normal_scale.map_or(1.0, |s| s.0),
            encoding: NormalEncoding::TangentSpace,
        });
        if m.textures.metallic_roughness.is_some() && !is_mr {
            let at = d.metallic_roughness_texture.as_ref().map_or(span, |t| t.span());
            return Err(self.err(
                at,
                format!("material `{name}`: `metallic_roughness_texture` needs `model = \"metallic_roughness\"`"),
            ));
        }
        Ok(m)
    }

    /// Adds the texture of `file` (relative to the scene file) for `slot` of material `name`,
    /// decoding the image once; a file that cannot be read is a warning.
    #[allow(clippy::too_many_arguments)]
    fn texture(
        &self,
        name: &str,
        slot: &str,
        file: &str,
        sampler: Sampler,
        textures: &mut Vec<Arc<Texture>>,
        loader: &mut TextureLoader,
        warnings: &mut Vec<String>,
    ) -> TextureId {
        let path = self.dir.join(file);
        let label = Path::new(file).file_name().map_or(file.to_owned(), |n| n.to_string_lossy().into_owned());
        let source = TextureSource::File(path.clone());
        let texture = match loader.file(&path) {
            Ok(image) => Texture::new(label, source, sampler, image),
            Err(e) => {
                warnings.push(format!(
                    "material `{name}`: the {slot} texture {}: {e}; {}",
                    path.display(),
                    crate::material_eval::fallback_text(slot)
                ));
                Texture::unreadable(label, source, sampler, e)
            }
        };
        textures.push(Arc::new(texture));
        (textures.len() - 1) as TextureId
    }
}
