//! The mapping of MTL materials onto englobe's (documented in `docs/scene-format.md`, "MTL
//! materials"). MTL describes the Phong-style shading of Wavefront's Advanced Visualizer; englobe
//! maps it onto the microfacet materials glTF files get (the metallic-roughness model over the
//! Trowbridge-Reitz distribution, see `englobe_render::bsdf`), so that an OBJ renders with the
//! same physically based scattering as a glTF:
//!
//! | MTL | englobe |
//! |---|---|
//! | `Kd`, `map_Kd` | base colour and its texture (sRGB) |
//! | `Ka` | the diffuse colour when `Kd` is black, `Ka` is not and there is no `map_Kd` (a warning says so) |
//! | `Ns` | roughness: the GGX width with the Phong lobe's peak, `alpha = sqrt(2 / (Ns + 2))` (Walter, Marschner, Li and Torrance 2007, section 5.2); perceptual roughness `sqrt(alpha)`; 32 when absent |
//! | `Ks` black, or `illum` 0 and 1 | Lambert (no specular layer: index 1) |
//! | `Ks` and `Kd` not black, `illum` 2 | plastic: Lambert `Kd` under a dielectric layer of index `Ni` (1.5 when not above 1), rough by `Ns` |
//! | `Kd` black, `Ks` not, `illum` 2 | a rough conductor of reflectance `Ks` (metallic 1, base colour `Ks`, `map_Ks` its texture) |
//! | `illum` 3, 5 (and 6, 7 with `d` 1): mirrors | smooth; `Kd` diffuse and a mirror of `Ks`: metallic `max Ks / (max Kd + max Ks)`, base colour `min(Kd + Ks, 1)` (exact when `Kd` and `Ks` are grey, proportional, or one is black) |
//! | `illum` 4, 6, 7, 9 with `d` < 1: glass | smooth dielectric of index `Ni` (1.5 when not above 0), transmission `1 - d` (`Tr` = 1 - `d` when `d` is absent), tinted by `Tf` (white when absent) |
//! | other `illum`, `d` < 1 | coverage: `alpha_mode` blend, alpha `d` (dissolve) |
//! | `Ke`, `map_Ke` | `emission` and its texture (`map_Ke` without `Ke` glows at 1) |
//! | `map_d` | coverage texture, cut out below 0.5 (`alpha_mode` mask), times `d` |
//! | `norm` | tangent-space normal map, `-bm` its scale |
//! | `bump`, `map_Bump` | height map (`-imfchan`, luminance by default; `-bm` its scale), or a normal map when the image is one (blue around 1, red and green around 0.5 on average) |
//! | `Pr`, `Pm` (the PBR extension) | roughness `Pr` (default from `Ns`), metalness `Pm` (default 0), base colour `Kd`, index `Ni` |
//!
//! The classic fields (`specular`, `shininess`, `reflectivity`, `transparency`) keep the MTL's
//! numbers for the Whitted integrator, which reads mirrors and glass from them; `diffuse` is the
//! base colour.
//!
//! Texture options: `-o` and `-s` become the texture transform (applied in OBJ's coordinates, `v`
//! up), `-clamp on` clamps to the edge, `-imfchan` picks the channel of `map_d` and bump maps and
//! `-mm` remaps their values; `-blendu`, `-blendv`, `-boost`, `-cc`, `-t`, `-texres` and `-type`
//! are read and have no effect. `map_Ka`, `map_Ns`, `disp`, `decal` and `refl` are read and not
//! used. Paths are relative to the MTL file (`\\` read as `/` when the name is not found as is).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use englobe::Vec3;
use glam::Vec2;

use super::mtl_map::MapStatement;
use crate::material::{
    Alpha, AlphaMode, Channel, Material, MaterialModel, NormalEncoding, NormalMap, ScalarTexture, TextureRef,
    UvTransform, shininess_to_roughness,
};
use crate::material_eval::fallback_text;
use crate::texture::{ColorSpace, Sampler, TexelImage, Texture, TextureId, TextureLoader, TextureSource, Wrap};

/// The textures of one OBJ file's materials, each image decoded once.
#[derive(Default)]
pub(super) struct MtlTextures {
    loader: TextureLoader,
    pub textures: Vec<Arc<Texture>>,
    ids: HashMap<(PathBuf, Sampler), TextureId>,
    pub warnings: Vec<String>,
}

/// The texture coordinate transform of `-o` and `-s`: OBJ's `(u, v_obj)` becomes
/// `s * (u, v_obj) + o`; englobe's coordinates have `v = 1 - v_obj`, so the same map reads
/// `v' = 1 - (s_v * (1 - v) + o_v) = s_v * v + (1 - s_v - o_v)`.
fn uv_transform(m: &MapStatement) -> Option<UvTransform> {
    let (o, s) = (m.options.o, m.options.s);
    if o[..2] == [0.0, 0.0] && s[..2] == [1.0, 1.0] {
        return None;
    }
    Some(UvTransform { offset: Vec2::new(o[0], 1.0 - s[1] - o[1]), rotation: 0.0, scale: Vec2::new(s[0], s[1]) })
}

fn channel(c: Option<char>, default: Channel) -> Channel {
    match c {
        Some('r') => Channel::Red,
        Some('g') => Channel::Green,
        Some('b') => Channel::Blue,
        Some('m') => Channel::Alpha,
        Some('l') => Channel::Luminance,
        // `z` (depth) means nothing for an image file; the default channel is read.
        _ => default,
    }
}

/// True when `image` looks like a tangent-space normal map: on average blue near 1 and red
/// and green near one half (sampled on a grid of at most 64 x 64 texels).
fn looks_like_normal_map(image: &TexelImage) -> bool {
    if image.channels() < 3 {
        return false;
    }
    let (w, h) = (image.width(), image.height());
    let (sx, sy) = (w.div_ceil(64).max(1), h.div_ceil(64).max(1));
    let (mut sum, mut n) = (Vec3::ZERO, 0.0);
    for y in (0..h).step_by(sy as usize) {
        for x in (0..w).step_by(sx as usize) {
            sum += image.fetch(x, y, ColorSpace::Linear).truncate();
            n += 1.0;
        }
    }
    let mean = sum / n;
    mean.z > 0.75 && (0.35..0.65).contains(&mean.x) && (0.35..0.65).contains(&mean.y)
}

impl MtlTextures {
    /// The texture of statement `m` of material `material` (in the library of folder `dir`),
    /// warning when it cannot be read.
    fn texture(&mut self, dir: &Path, material: &str, slot: &str, m: &MapStatement) -> TextureRef {
        let mut file = dir.join(&m.file);
        if !file.is_file() && m.file.contains('\\') {
            file = dir.join(m.file.replace('\\', "/"));
        }
        let wrap = if m.options.clamp { Wrap::ClampToEdge } else { Wrap::Repeat };
        let sampler = Sampler::wrapping(wrap);
        let key = (file.clone(), sampler);
        let id = match self.ids.get(&key) {
            Some(&id) => id,
            None => {
                let name = Path::new(&m.file).file_name().map_or(m.file.clone(), |n| n.to_string_lossy().into_owned());
                let source = TextureSource::File(file.clone());
                let texture = match self.loader.file(&file) {
                    Ok(image) => Texture::new(name, source, sampler, image),
                    Err(e) => Texture::unreadable(name, source, sampler, e),
                };
                self.textures.push(Arc::new(texture));
                let id = (self.textures.len() - 1) as TextureId;
                self.ids.insert(key, id);
                id
            }
        };
        if let Some(e) = &self.textures[id as usize].error {
            self.warnings.push(format!(
                "material `{material}`: the {slot} texture {}: {e}; {}",
                file.display(),
                fallback_text(slot)
            ));
        }
        TextureRef { texture: id, uv_set: 0, transform: uv_transform(m) }
    }

    fn image(&self, r: &TextureRef) -> Option<&TexelImage> {
        self.textures.get(r.texture as usize)?.image.as_deref()
    }
}

/// The MTL numbers the microfacet mapping reads.
struct MtlLobes {
    /// `Kd` (or `Ka` in its place).
    diffuse: Vec3,
    /// `Ks`, black under `illum` 0 and 1.
    specular: Vec3,
    /// `Ns`.
    shininess: f32,
    illum: Option<u8>,
    /// `1 - d` for glass, else 0.
    transmission: f32,
    /// `Ni`, when above 0.
    ni: Option<f32>,
    /// `Tf`.
    tint: Option<Vec3>,
}

/// The metallic-roughness parameters of an MTL material (the module's table).
#[derive(Debug, PartialEq)]
struct Layers {
    base_color: Vec3,
    metallic: f32,
    roughness: f32,
    ior: f32,
    /// True for a conductor whose colour is `Ks`: `map_Ks` is then its base colour texture.
    metal_from_specular: bool,
}

fn layers(l: &MtlLobes) -> Layers {
    let (kd, ks) = (l.diffuse.max_element(), l.specular.max_element());
    let glossy = shininess_to_roughness(l.shininess);
    // Index 1: no dielectric layer, so a surface without a highlight is Lambertian.
    let lambert =
        Layers { base_color: l.diffuse, metallic: 0.0, roughness: glossy, ior: 1.0, metal_from_specular: false };
    if l.transmission > 0.0 {
        let base_color = l.tint.unwrap_or(Vec3::ONE);
        return Layers {
            base_color,
            metallic: 0.0,
            roughness: 0.0,
            ior: l.ni.unwrap_or(1.5),
            metal_from_specular: false,
        };
    }
    if ks <= 0.0 {
        return lambert;
    }
    if matches!(l.illum, Some(3 | 5 | 6 | 7)) {
        // A mirror of reflectance Ks beside a diffuse Kd: the metal's share and the diffuse
        // share of one base colour reflect Ks and Kd (scaled down together where they sum
        // above 1).
        let base_color = (l.diffuse + l.specular).min(Vec3::ONE);
        return Layers { base_color, metallic: ks / (kd + ks), roughness: 0.0, ..lambert };
    }
    if kd <= 0.0 {
        return Layers { base_color: l.specular, metallic: 1.0, metal_from_specular: true, ..lambert };
    }
    Layers { ior: l.ni.filter(|n| *n > 1.0).unwrap_or(1.5), ..lambert }
}

/// englobe's material for the checked MTL material `m`, whose texture statements are `maps`
/// (from the library in folder `dir`).
pub(super) fn to_material(
    m: &tobj::Material,
    maps: &[(String, MapStatement)],
    dir: &Path,
    tex: &mut MtlTextures,
) -> Material {
    let base = Material::default();
    let name = m.name.as_str();
    let color = |c: Option<[f32; 3]>, default: Vec3| c.map_or(default, |c| Vec3::from(c).max(Vec3::ZERO));
    let map = |keys: &[&str]| maps.iter().rev().find(|(k, _)| keys.contains(&k.as_str())).map(|(_, s)| s);
    let illum = m.illumination_model;
    let specular = match illum {
        Some(0) | Some(1) => Vec3::ZERO,
        _ => color(m.specular, base.specular),
    };
    let param = |key: &str| {
        m.unknown_param
            .get(key)
            .and_then(|t| t.split_whitespace().next()?.parse::<f32>().ok())
            .filter(|v| v.is_finite())
    };
    // `Tr` is what `tobj` keeps as an unknown parameter; `scan` checked that it is a number.
    let dissolve = m.dissolve.or(param("Tr").map(|t| 1.0 - t)).unwrap_or(1.0).clamp(0.0, 1.0);
    let glass = matches!(illum, Some(4 | 6 | 7 | 9));
    let transparency = if glass { 1.0 - dissolve } else { 0.0 };
    let reflectivity = match illum {
        Some(3 | 5 | 6 | 7) => specular.max_element().clamp(0.0, 1.0 - transparency),
        _ => 0.0,
    };
    let mut diffuse = color(m.diffuse, base.diffuse);
    let ambient = color(m.ambient, Vec3::ZERO);
    let diffuse_map = map(&["map_Kd"]);
    if diffuse == Vec3::ZERO && ambient != Vec3::ZERO && diffuse_map.is_none() {
        tex.warnings.push(format!(
            "material `{name}`: no diffuse colour (Kd 0 0 0) but an ambient one (Ka {} {} {}); Ka is used as the diffuse colour",
            ambient.x, ambient.y, ambient.z
        ));
        diffuse = ambient;
    }
    let emission_map = map(&["map_Ke"]);
    let mut emission = color(m.emissive, Vec3::ZERO);
    if emission == Vec3::ZERO && emission_map.is_some() {
        emission = Vec3::ONE;
    }
    let shininess = m.shininess.filter(|s| *s >= 0.0).unwrap_or(base.shininess);
    let (pr, pm) = (param("Pr"), param("Pm"));
    let ni = m.optical_density.filter(|n| *n > 0.0);
    let layers = if pr.is_some() || pm.is_some() {
        Layers {
            base_color: diffuse,
            metallic: pm.unwrap_or(0.0).clamp(0.0, 1.0),
            roughness: pr.unwrap_or_else(|| shininess_to_roughness(shininess)).clamp(0.0, 1.0),
            ior: ni.unwrap_or(base.ior),
            metal_from_specular: false,
        }
    } else {
        let tint = m.unknown_param.get("Tf").and_then(|t| {
            let v: Vec<f32> = t.split_whitespace().map_while(|w| w.parse().ok()).collect();
            (v.len() == 3).then(|| Vec3::new(v[0], v[1], v[2]).clamp(Vec3::ZERO, Vec3::ONE))
        });
        layers(&MtlLobes { diffuse, specular, shininess, illum, transmission: transparency, ni, tint })
    };
    let mut material = Material {
        diffuse: layers.base_color,
        specular,
        shininess,
        reflectivity,
        transparency,
        ior: layers.ior,
        emission,
        model: MaterialModel::MetallicRoughness {
            metallic: layers.metallic,
            roughness: layers.roughness,
            transmission: transparency,
        },
        alpha: Alpha {
            mode: if !glass && dissolve < 1.0 { AlphaMode::Blend } else { AlphaMode::Opaque },
            factor: if glass { 1.0 } else { dissolve },
        },
        ..base
    };
    let specular_map = map(&["map_Ks"]);
    let t = &mut material.textures;
    t.base_color = match (layers.metal_from_specular, specular_map) {
        (true, Some(s)) => Some(tex.texture(dir, name, "specular", s)),
        _ => diffuse_map.map(|s| tex.texture(dir, name, "base colour", s)),
    };
    t.specular = specular_map.map(|s| tex.texture(dir, name, "specular", s));
    t.emission = emission_map.map(|s| tex.texture(dir, name, "emission", s));
    if let Some(s) = map(&["map_d"]) {
        let texture = tex.texture(dir, name, "alpha", s);
        let has_alpha = tex.image(&texture).is_some_and(|i| i.channels() == 2 || i.channels() == 4);
        let default = if has_alpha { Channel::Alpha } else { Channel::Luminance };
        let remap = (s.options.mm != [0.0, 1.0]).then_some(s.options.mm);
        t.alpha = Some(ScalarTexture { texture, channel: channel(s.options.imfchan, default), remap });
        material.alpha = Alpha { mode: AlphaMode::Mask { cutoff: 0.5 }, factor: dissolve };
    }
    if let Some(s) = map(&["norm"]) {
        let texture = tex.texture(dir, name, "normal", s);
        material.textures.normal =
            Some(NormalMap { texture, scale: s.options.bm, encoding: NormalEncoding::TangentSpace });
    } else if let Some(s) = map(&["bump", "map_Bump", "map_bump"]) {
        let texture = tex.texture(dir, name, "bump", s);
        let normal_map = s.options.imfchan.is_none() && tex.image(&texture).is_some_and(looks_like_normal_map);
        let encoding = if normal_map {
            tex.warnings.push(format!("material `{name}`: the bump map {} is a normal map; it is read as one", s.file));
            NormalEncoding::TangentSpace
        } else {
            NormalEncoding::Height(channel(s.options.imfchan, Channel::Luminance))
        };
        material.textures.normal = Some(NormalMap { texture, scale: s.options.bm, encoding });
    }
    for (keyword, s) in maps {
        if matches!(
            keyword.as_str(),
            "map_Ka" | "map_Ns" | "map_ns" | "map_NS" | "disp" | "decal" | "refl" | "map_Pr" | "map_Pm"
        ) {
            tex.warnings.push(format!("material `{name}`: `{keyword} {}` is read but not used", s.file));
        }
    }
    material
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::mtl::scan;

    fn one(text: &str) -> (Material, MtlTextures) {
        let scanned = scan(Path::new("t.mtl"), text).unwrap();
        let (mats, _) = tobj::load_mtl_buf(&mut scanned.text.as_bytes()).unwrap();
        let mut tex = MtlTextures::default();
        let maps = &scanned.maps;
        let m = to_material(&mats[0], maps.get(&mats[0].name).map_or(&[][..], Vec::as_slice), Path::new("."), &mut tex);
        (m, tex)
    }

    #[test]
    fn mapping_follows_the_table() {
        let (m, _) = one("newmtl glass\nKd 0.1 0.2 0.3\nKs 0.9 0.8 0.7\nNs 50\nNi 1.33\nTr 0.25\nillum 7\nKe 0 1 0\n");
        assert_eq!(m.diffuse, Vec3::ONE, "glass without Tf is clear");
        assert_eq!(m.model, MaterialModel::MetallicRoughness { metallic: 0.0, roughness: 0.0, transmission: 0.25 });
        assert_eq!((m.shininess, m.ior, m.transparency), (50.0, 1.33, 0.25));
        assert_eq!(m.reflectivity, 0.75, "Ks 0.9, capped at 1 - transparency");
        assert_eq!((m.emission, m.alpha), (Vec3::Y, Alpha::default()));
        let (m, _) = one("newmtl m\nKs 1 1 1\nillum 1\nd 1\nTr 0.5\n");
        assert_eq!(
            (m.specular, m.transparency, m.reflectivity, m.alpha.mode),
            (Vec3::ZERO, 0.0, 0.0, AlphaMode::Opaque),
            "d wins over Tr"
        );
    }

    #[test]
    fn illumination_models() {
        let with = |illum: u32| one(&format!("newmtl m\nKd 0.5 0.5 0.5\nKs 0.6 0.6 0.6\nd 0.8\nillum {illum}\n")).0;
        for illum in [0, 1, 2] {
            let m = with(illum);
            assert_eq!((m.reflectivity, m.transparency), (0.0, 0.0), "illum {illum}");
            assert_eq!(m.alpha, Alpha { mode: AlphaMode::Blend, factor: 0.8 }, "dissolve is coverage");
        }
        assert_eq!(with(1).specular, Vec3::ZERO);
        assert_eq!(with(2).specular, Vec3::splat(0.6));
        for illum in [3, 5] {
            assert_eq!((with(illum).reflectivity, with(illum).transparency), (0.6, 0.0), "illum {illum}");
        }
        for illum in [4, 9] {
            let m = with(illum);
            assert!(
                (m.transparency - 0.2).abs() < 1e-6 && m.reflectivity == 0.0 && m.alpha.mode == AlphaMode::Opaque,
                "{illum}"
            );
        }
        for illum in [6, 7] {
            let m = with(illum);
            assert!((m.transparency - 0.2).abs() < 1e-6 && m.reflectivity == 0.6, "{illum}");
        }
        assert_eq!(with(8).reflectivity, 0.0, "illum 8 reflects a map, not rays");
    }

    /// Base colour, metalness, roughness, transmission and index.
    type Mapped = (Vec3, f32, f32, f32, f32);

    /// The base colour, metalness, roughness, transmission and index of the material of `text`.
    fn microfacet(text: &str) -> Mapped {
        let (m, _) = one(text);
        let MaterialModel::MetallicRoughness { metallic, roughness, transmission } = m.model else {
            panic!("{:?}", m.model)
        };
        (m.diffuse, metallic, roughness, transmission, m.ior)
    }

    fn close(a: Mapped, b: Mapped) -> bool {
        (a.0 - b.0).abs().max_element() < 1e-6
            && [a.1 - b.1, a.2 - b.2, a.3 - b.3, a.4 - b.4].iter().all(|d| d.abs() < 1e-6)
    }

    #[test]
    fn microfacet_mapping_row_by_row() {
        let red = Vec3::new(0.6, 0.1, 0.1);
        // Ns 98: alpha = sqrt(2 / 100), roughness = alpha^(1/2).
        let r98 = (2.0f32 / 100.0).sqrt().sqrt();
        let rows: [(&str, Mapped); 9] = [
            // Ks black: Lambert, no layer (index 1), whatever Ni says.
            ("Kd 0.6 0.1 0.1\nKs 0 0 0\nNs 98\nNi 1.5\nillum 2", (red, 0.0, r98, 0.0, 1.0)),
            // illum 1 has no highlight: Ks is not read.
            ("Kd 0.6 0.1 0.1\nKs 1 1 1\nNs 98\nillum 1", (red, 0.0, r98, 0.0, 1.0)),
            // Plastic: Kd under a layer of index Ni, rough by Ns.
            ("Kd 0.6 0.1 0.1\nKs 0.5 0.5 0.5\nNs 98\nNi 1.4\nillum 2", (red, 0.0, r98, 0.0, 1.4)),
            // ... 1.5 where Ni is not above 1.
            ("Kd 0.6 0.1 0.1\nKs 0.5\nNs 98\nNi 1\nillum 2", (red, 0.0, r98, 0.0, 1.5)),
            // Kd black: a conductor of reflectance Ks.
            ("Kd 0 0 0\nKs 0.9 0.6 0.2\nNs 98\nillum 2", (Vec3::new(0.9, 0.6, 0.2), 1.0, r98, 0.0, 1.0)),
            // Mirrors: Kd 0.3 diffuse and a mirror of 0.6: base 0.9, metal share 2/3.
            ("Kd 0.3\nKs 0.6\nNs 98\nillum 3", (Vec3::splat(0.9), 2.0 / 3.0, 0.0, 0.0, 1.0)),
            // ... scaled down together above 1 (Fresnel mirror, illum 5), and a plain mirror.
            ("Kd 0.8\nKs 0.8\nillum 5", (Vec3::ONE, 0.5, 0.0, 0.0, 1.0)),
            ("Kd 0 0 0\nKs 1 1 1\nillum 3", (Vec3::ONE, 1.0, 0.0, 0.0, 1.0)),
            // Glass: transmission 1 - d, index Ni, tint Tf.
            ("Kd 0.5\nKs 1\nd 0.1\nNi 1.33\nTf 0.9 1 0.8\nillum 4", (Vec3::new(0.9, 1.0, 0.8), 0.0, 0.0, 0.9, 1.33)),
        ];
        for (body, want) in rows {
            let got = microfacet(&format!("newmtl m\n{body}\n"));
            assert!(close(got, want), "{body}: {got:?}, want {want:?}");
        }
        // illum 6 and 7 with d = 1 are mirrors; with d < 1, glass (Tf absent: clear, Ni absent: 1.5).
        assert!(close(microfacet("newmtl m\nKd 0 0 0\nKs 1\nillum 7\n"), (Vec3::ONE, 1.0, 0.0, 0.0, 1.0)));
        assert!(close(microfacet("newmtl m\nKd 0.2\nKs 1\nd 0\nillum 6\n"), (Vec3::ONE, 0.0, 0.0, 1.0, 1.5)));
        // Ns absent: 32.
        assert_eq!(microfacet("newmtl m\nKd 0.5\nKs 0.5\n").2, shininess_to_roughness(32.0));
    }

    #[test]
    fn colour_forms_reach_the_material() {
        // `Kd r` is grey; `Ks xyz` is converted; `Ka spectral` keeps the default (black) and warns.
        let (m, _) = one("newmtl m\nKd 0.25\nKs xyz 0.9505 1.0 1.089\nKa spectral a.rfl\nillum 3\n");
        assert!((m.specular - Vec3::ONE).abs().max_element() < 2e-3, "{}", m.specular);
        let MaterialModel::MetallicRoughness { metallic, .. } = m.model else { panic!() };
        assert!((metallic - 0.8).abs() < 1e-3, "Ks 1 beside Kd 0.25: {metallic}");
        // `Tf xyz` tints glass.
        let (m, _) = one("newmtl m\nTf xyz 0.5\nd 0\nillum 4\n");
        assert!(
            (m.diffuse - Vec3::new(0.6024, 0.4742, 0.4544).min(Vec3::ONE)).abs().max_element() < 1e-3,
            "{}",
            m.diffuse
        );
    }

    #[test]
    fn a_conductor_reads_its_colour_from_map_ks() {
        let (m, _) = one("newmtl m\nKd 0 0 0\nKs 1 1 1\nmap_Kd kd.png\nmap_Ks ks.png\n");
        let tex = |r: Option<TextureRef>| r.map(|r| r.texture);
        assert_eq!(tex(m.textures.base_color), tex(m.textures.specular), "map_Ks is the conductor's colour");
        let (m, _) = one("newmtl m\nKd 0.5 0.5 0.5\nKs 1 1 1\nmap_Kd kd.png\nmap_Ks ks.png\n");
        assert_ne!(tex(m.textures.base_color), tex(m.textures.specular), "a plastic's base colour is map_Kd");
    }

    #[test]
    fn black_diffuse_with_an_ambient_colour_takes_it() {
        let (m, tex) = one("newmtl box\nKa 0.725 0.71 0.68\nKd 0 0 0\nKs 0.725 0.71 0.68\nNs 200\nillum 2\n");
        assert_eq!(m.diffuse, Vec3::new(0.725, 0.71, 0.68));
        assert_eq!(m.specular, Vec3::new(0.725, 0.71, 0.68));
        assert!(tex.warnings[0].contains("Ka is used"), "{:?}", tex.warnings);
        let (m, tex) = one("newmtl black\nKa 0 0 0\nKd 0 0 0\n");
        assert_eq!((m.diffuse, tex.warnings.len()), (Vec3::ZERO, 0), "a black material stays black");
    }

    #[test]
    fn pbr_extension_and_missing_textures() {
        let (m, tex) = one(
            "newmtl p\nKd 0.5 0.5 0.5\nPr 0.3\nPm 1\nmap_Kd -o 0.25 0.5 -s 2 3 nowhere.png\nnorm -bm 0.5 nowhere_n.png\n",
        );
        assert_eq!(m.model, MaterialModel::MetallicRoughness { metallic: 1.0, roughness: 0.3, transmission: 0.0 });
        let base = m.textures.base_color.unwrap();
        // OBJ's v up: v_obj' = 3 v_obj + 0.5, so v' = 3 v + (1 - 3 - 0.5).
        assert_eq!(
            base.transform.unwrap(),
            UvTransform { offset: Vec2::new(0.25, -2.5), rotation: 0.0, scale: Vec2::new(2.0, 3.0) }
        );
        let n = m.textures.normal.unwrap();
        assert_eq!((n.scale, n.encoding), (0.5, NormalEncoding::TangentSpace));
        assert_eq!(tex.textures.len(), 2);
        assert!(tex.textures.iter().all(|t| t.image.is_none()));
        assert!(
            tex.warnings.iter().any(|w| w.contains("`p`") && w.contains("nowhere.png") && w.contains("magenta")),
            "{:?}",
            tex.warnings
        );
    }

    #[test]
    fn the_uv_transform_matches_obj_coordinates() {
        let (m, _) = one("newmtl p\nmap_Kd -o 0.1 0.2 -s 0.5 0.25 t.png\n");
        let t = m.textures.base_color.unwrap().transform.unwrap();
        for (u, v_obj) in [(0.0f32, 0.0f32), (0.3, 0.9), (1.0, 0.5)] {
            let want_obj = Vec2::new(0.5 * u + 0.1, 0.25 * v_obj + 0.2);
            let got = t.apply(Vec2::new(u, 1.0 - v_obj));
            assert!((got - Vec2::new(want_obj.x, 1.0 - want_obj.y)).length() < 1e-6);
        }
    }
}
