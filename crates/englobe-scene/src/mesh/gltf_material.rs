//! glTF 2.0 materials and their textures (Khronos Group, glTF 2.0 Specification, sections 3.8
//! "Texture Data" and 3.9 "Materials"): the metallic-roughness factors and textures, the normal
//! texture and its scale, the emissive factor and texture with `KHR_materials_emissive_strength`,
//! `alphaMode` and `alphaCutoff`, `doubleSided`, `KHR_materials_transmission` and
//! `KHR_materials_ior`, and `KHR_texture_transform` on the textures that carry it (the `gltf`
//! crate keeps it on all but the normal and occlusion textures). The occlusion texture is kept
//! for ambient terms (a path tracer computes the occlusion it approximates). Each texture keeps
//! its `texCoord` (or the transform's), set 0 or 1; higher sets are read with set 0.
//!
//! Images come from files beside the `.gltf` (URIs relative to it, percent-decoded), `data:`
//! URIs, or buffer views (the GLB binary chunk). Each glTF texture becomes one
//! [`Texture`], its image decoded once; a texture that cannot be read is a warning naming the
//! material, the slot and the file, and the slot's fallback (see [`crate::material_eval`]).

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use englobe::Vec3;
use glam::Vec2;
use gltf::json;
use gltf::json::texture::{MagFilter, WrappingMode};
use gltf::json::validation::Checked;

use super::gltf_data::{Buffers, decode_base64, percent_decode};
use super::loaded::NamedMaterial;
use crate::material::{
    Alpha, AlphaMode, Channel, Material, MaterialModel, NormalEncoding, NormalMap, ScalarTexture, TextureRef,
    UvTransform,
};
use crate::material_eval::fallback_text;
use crate::texture::{Filter, Sampler, Texture, TextureId, TextureLoader, TextureSource, Wrap};

/// The materials of a document, the textures they use and what went wrong reading them.
#[derive(Default)]
pub(super) struct GltfMaterials {
    pub materials: Vec<NamedMaterial>,
    pub textures: Vec<Arc<Texture>>,
    pub warnings: Vec<String>,
}

struct Reader<'a, 'b> {
    path: &'a Path,
    root: &'a json::Root,
    buffers: &'b mut Buffers<'a>,
    loader: TextureLoader,
    /// glTF texture index to englobe texture.
    ids: HashMap<usize, TextureId>,
    out: GltfMaterials,
}

/// Reads every material of `root` and the textures they name.
pub(super) fn materials<'a>(path: &'a Path, root: &'a json::Root, buffers: &mut Buffers<'a>) -> GltfMaterials {
    let mut r = Reader {
        path,
        root,
        buffers,
        loader: TextureLoader::default(),
        ids: HashMap::new(),
        out: GltfMaterials::default(),
    };
    for (i, m) in root.materials.iter().enumerate() {
        let name = m.name.clone().unwrap_or_else(|| format!("material {i}"));
        let material = r.material(&name, m);
        r.out.materials.push((name, material));
    }
    r.out
}

/// `v` if finite, else `default`.
fn finite(v: f32, default: f32) -> f32 {
    if v.is_finite() { v } else { default }
}

impl Reader<'_, '_> {
    fn material(&mut self, name: &str, m: &json::Material) -> Material {
        let pbr = &m.pbr_metallic_roughness;
        let [r, g, b, a] = pbr.base_color_factor.0.map(|c| finite(c, 1.0).max(0.0));
        let ext = m.extensions.as_ref();
        let transmission = ext.and_then(|e| e.transmission.as_ref());
        let strength =
            ext.and_then(|e| e.emissive_strength.as_ref()).map_or(1.0, |s| finite(s.emissive_strength.0, 1.0).max(0.0));
        let ior = ext.and_then(|e| e.ior.as_ref()).map_or(1.5, |i| finite(i.ior.0, 1.5));
        let emission = Vec3::from(m.emissive_factor.0.map(|c| finite(c, 0.0).max(0.0))) * strength;
        let mode = match m.alpha_mode {
            Checked::Valid(json::material::AlphaMode::Mask) => {
                AlphaMode::Mask { cutoff: m.alpha_cutoff.map_or(0.5, |c| finite(c.0, 0.5).max(0.0)) }
            }
            Checked::Valid(json::material::AlphaMode::Blend) => AlphaMode::Blend,
            _ => AlphaMode::Opaque,
        };
        let mut material = Material {
            diffuse: Vec3::new(r, g, b),
            emission: if emission.is_finite() { emission } else { Vec3::ZERO },
            // An index of 0 stands for "infinitely dense"; indices below 1 are not physical.
            ior: if ior >= 1.0 { ior } else { 1.5 },
            model: MaterialModel::MetallicRoughness {
                metallic: finite(pbr.metallic_factor.0, 1.0).clamp(0.0, 1.0),
                roughness: finite(pbr.roughness_factor.0, 1.0).clamp(0.0, 1.0),
                transmission: transmission.map_or(0.0, |t| finite(t.transmission_factor.0, 0.0).clamp(0.0, 1.0)),
            },
            alpha: Alpha { mode, factor: a.min(1.0) },
            double_sided: m.double_sided,
            ..Material::default()
        };
        let t = &mut material.textures;
        t.base_color = pbr.base_color_texture.as_ref().and_then(|i| self.info(name, "base colour", i));
        t.metallic_roughness =
            pbr.metallic_roughness_texture.as_ref().and_then(|i| self.info(name, "metallic-roughness", i));
        t.emission = m.emissive_texture.as_ref().and_then(|i| self.info(name, "emission", i));
        t.normal = m.normal_texture.as_ref().and_then(|n| {
            let texture = self.reference(name, "normal", n.index.value(), n.tex_coord, None)?;
            Some(NormalMap { texture, scale: finite(n.scale, 1.0), encoding: NormalEncoding::TangentSpace })
        });
        t.occlusion = m.occlusion_texture.as_ref().and_then(|o| {
            let texture = self.reference(name, "occlusion", o.index.value(), o.tex_coord, None)?;
            let strength = finite(o.strength.0, 1.0).clamp(0.0, 1.0);
            Some(ScalarTexture { texture, channel: Channel::Red, remap: Some([1.0 - strength, strength]) })
        });
        if transmission.is_some_and(|t| t.transmission_texture.is_some()) {
            self.out
                .warnings
                .push(format!("material `{name}`: the transmission texture is not read; its factor is used"));
        }
        material
    }

    fn info(&mut self, material: &str, slot: &str, info: &json::texture::Info) -> Option<TextureRef> {
        let transform = info.extensions.as_ref().and_then(|e| e.texture_transform.as_ref());
        let uv = transform.map(|t| UvTransform {
            offset: Vec2::from(t.offset.0.map(|c| finite(c, 0.0))),
            rotation: finite(t.rotation.0, 0.0),
            scale: Vec2::from(t.scale.0.map(|c| finite(c, 1.0))),
        });
        let set = transform.and_then(|t| t.tex_coord).unwrap_or(info.tex_coord);
        self.reference(material, slot, info.index.value(), set, uv)
    }

    fn reference(
        &mut self,
        material: &str,
        slot: &str,
        index: usize,
        set: u32,
        transform: Option<UvTransform>,
    ) -> Option<TextureRef> {
        let Some(texture) = self.texture(index) else {
            self.out.warnings.push(format!(
                "material `{material}`: the {slot} texture refers to textures[{index}], which does not exist; {}",
                fallback_text(slot)
            ));
            return None;
        };
        // Meshes keep sets 0 and 1 (see `super::gltf`); a texture asking for another is read
        // with set 0, and its reference says so.
        let set = if set > 1 {
            self.out.warnings.push(format!(
                "material `{material}`: the {slot} texture uses TEXCOORD_{set}; englobe reads TEXCOORD_0 and TEXCOORD_1 only and samples it with TEXCOORD_0"
            ));
            0
        } else {
            set
        };
        let t = &self.out.textures[texture as usize];
        if let Some(e) = &t.error {
            self.out.warnings.push(format!(
                "material `{material}`: the {slot} texture {}: {e}; {}",
                t.source,
                fallback_text(slot)
            ));
        }
        Some(TextureRef { texture, uv_set: set, transform })
    }

    /// The englobe texture of glTF texture `index`, read on first use; `None` if there is no
    /// such texture.
    fn texture(&mut self, index: usize) -> Option<TextureId> {
        if let Some(&id) = self.ids.get(&index) {
            return Some(id);
        }
        let def = self.root.textures.get(index)?;
        let sampler = def.sampler.and_then(|s| self.root.samplers.get(s.value())).map_or(Sampler::default(), sampler);
        let image_index = def.source.value();
        let (name, source, image) = match self.root.images.get(image_index) {
            None => (
                format!("textures[{index}]"),
                TextureSource::Embedded(format!("images[{image_index}]")),
                Err("the image does not exist".to_owned()),
            ),
            Some(image) => self.image(image_index, image),
        };
        let name =
            def.name.clone().or_else(|| self.root.images.get(image_index).and_then(|i| i.name.clone())).unwrap_or(name);
        let texture = match image {
            Ok(img) => Texture::new(name, source, sampler, img),
            Err(e) => Texture::unreadable(name, source, sampler, e),
        };
        self.out.textures.push(Arc::new(texture));
        let id = (self.out.textures.len() - 1) as TextureId;
        self.ids.insert(index, id);
        Some(id)
    }

    /// The decoded image `images[index]`, its name and its source.
    fn image(
        &mut self,
        index: usize,
        image: &json::Image,
    ) -> (String, TextureSource, Result<Arc<crate::texture::TexelImage>, String>) {
        let key = format!("images[{index}]");
        match (&image.uri, image.buffer_view) {
            (Some(uri), _) if uri.starts_with("data:") => {
                let result = self.loader.embedded(&key, || match uri.split_once(";base64,") {
                    Some((_, data)) => decode_base64(data),
                    None => Err("a data URI that is not base64".into()),
                });
                (key.clone(), TextureSource::Embedded(format!("{key} (data URI)")), result)
            }
            (Some(uri), _) if uri.contains("://") => {
                (uri.clone(), TextureSource::Embedded(key), Err(format!("the external URI `{uri}` is not fetched")))
            }
            (Some(uri), _) => {
                let decoded = percent_decode(uri);
                let file = self.path.parent().unwrap_or(Path::new("")).join(&decoded);
                let name =
                    Path::new(&decoded).file_name().map_or(decoded.clone(), |n| n.to_string_lossy().into_owned());
                (name, TextureSource::File(file.clone()), self.loader.file(&file))
            }
            (None, Some(view)) => {
                let view = view.value();
                let bytes = self.buffers.view(self.root, view).map(<[u8]>::to_vec).map_err(|e| e.to_string());
                let result = self.loader.embedded(&key, || bytes);
                (key.clone(), TextureSource::Embedded(format!("{key} (bufferViews[{view}])")), result)
            }
            (None, None) => {
                (key.clone(), TextureSource::Embedded(key), Err("the image has neither a uri nor a bufferView".into()))
            }
        }
    }
}

fn sampler(s: &json::texture::Sampler) -> Sampler {
    let wrap = |w: Checked<WrappingMode>| match w {
        Checked::Valid(WrappingMode::ClampToEdge) => Wrap::ClampToEdge,
        Checked::Valid(WrappingMode::MirroredRepeat) => Wrap::MirroredRepeat,
        _ => Wrap::Repeat,
    };
    let filter = match s.mag_filter {
        Some(Checked::Valid(MagFilter::Nearest)) => Filter::Nearest,
        _ => Filter::Bilinear,
    };
    Sampler { wrap_u: wrap(s.wrap_s), wrap_v: wrap(s.wrap_t), filter }
}
