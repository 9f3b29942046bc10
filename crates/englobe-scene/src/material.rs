//! Materials as the scene describes them: the classic model of the seed (Phong-style diffuse and
//! highlight, Whitted's mirror and glass) and the glTF 2.0 metallic-roughness model (Khronos
//! Group, glTF 2.0 Specification, section 3.9 and Appendix B), with the textures, alpha coverage
//! and sidedness of both. [`crate::material_eval`] turns a material and a texture coordinate
//! into the numbers a BSDF needs.
//!
//! A material keeps every field of the classic model, with today's meanings and defaults, so a
//! scene written before the metallic-roughness model renders as it did: the new fields default
//! to "classic, no textures, opaque, double-sided".

use glam::{Vec2, Vec3};

use crate::texture::TextureId;

/// Which reflection model a material follows.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum MaterialModel {
    /// The seed's model: `diffuse` (Lambert), `specular` and `shininess` (a Blinn-Phong
    /// highlight), `reflectivity` (a mirror), `transparency` and `ior` (Whitted's glass).
    #[default]
    Classic,
    /// glTF 2.0's metallic-roughness model. `Material::diffuse` holds the base colour factor
    /// (linear RGB), `Material::ior` the dielectric's index of refraction (1.5 unless
    /// `KHR_materials_ior` says otherwise) and `Material::emission` the emissive factor times
    /// `KHR_materials_emissive_strength`; `specular`, `shininess`, `reflectivity` and
    /// `transparency` are not used.
    MetallicRoughness {
        /// 0 dielectric, 1 metal (conductor whose Fresnel colour is the base colour).
        metallic: f32,
        /// Perceptual roughness in `0..=1`; the microfacet distribution's `alpha` is its square.
        roughness: f32,
        /// `KHR_materials_transmission`: the share of the dielectric base that transmits light
        /// (thin-walled or refracting by `ior`, as the renderer decides), in `0..=1`.
        transmission: f32,
    },
    /// A conductor of complex index `eta + i k` per RGB channel (pbrt-v4's `conductor`): a
    /// mirror when `alpha` is below 0.001, otherwise Trowbridge-Reitz (GGX) microfacet reflection
    /// of that `alpha`, both with the exact conductor Fresnel equations. The classic fields hold a
    /// stand-in for the Whitted integrator (a mirror or a diffuse colour).
    Conductor {
        /// Real part of the index, per channel.
        eta: Vec3,
        /// Imaginary part (absorption), per channel.
        k: Vec3,
        /// Microfacet roughness `alpha`.
        alpha: f32,
    },
    /// A dielectric of index `Material::ior` (pbrt-v4's `dielectric`): smooth glass when `alpha`
    /// is below 0.001, otherwise Walter et al.'s rough dielectric of that `alpha`.
    Dielectric {
        /// Microfacet roughness `alpha`.
        alpha: f32,
    },
    /// A diffuse base of colour `Material::diffuse` under a dielectric coat of index
    /// `Material::ior` and microfacet roughness `alpha` (pbrt-v4's `coateddiffuse`, rendered as
    /// the renderer's plastic BSDF: see docs/pbrt.md for what this approximates).
    CoatedDiffuse {
        /// Microfacet roughness `alpha` of the coat.
        alpha: f32,
    },
}

impl MaterialModel {
    /// The name used in scene files and by `englobe info`.
    pub fn name(&self) -> &'static str {
        match self {
            MaterialModel::Classic => "classic",
            MaterialModel::MetallicRoughness { .. } => "metallic_roughness",
            MaterialModel::Conductor { .. } => "conductor",
            MaterialModel::Dielectric { .. } => "dielectric",
            MaterialModel::CoatedDiffuse { .. } => "coated_diffuse",
        }
    }
}

/// `KHR_texture_transform`: `uv' = translation * rotation * scale * uv`, with the rotation
/// matrix `[[cos r, sin r], [-sin r, cos r]]` (counter-clockwise in the image, whose `v` points
/// down). MTL's `-o` and `-s` options are a transform without rotation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    /// Added last.
    pub offset: Vec2,
    /// Radians.
    pub rotation: f32,
    /// Applied first.
    pub scale: Vec2,
}

impl Default for UvTransform {
    fn default() -> Self {
        UvTransform { offset: Vec2::ZERO, rotation: 0.0, scale: Vec2::ONE }
    }
}

impl UvTransform {
    /// The transformed coordinate.
    #[inline]
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let s = uv * self.scale;
        let (sin, cos) = self.rotation.sin_cos();
        Vec2::new(cos * s.x + sin * s.y, -sin * s.x + cos * s.y) + self.offset
    }
}

/// A material's use of a texture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    /// Index into [`crate::Scene::textures`].
    pub texture: TextureId,
    /// Texture coordinate set (glTF's `texCoord`, or its `KHR_texture_transform`'s): 0 or 1,
    /// the sets meshes keep. Set 1 is read with set 0 on a mesh without one (the glTF loader
    /// warns); loaders map the sets englobe does not keep to 0, with a warning.
    pub uv_set: u32,
    /// Applied to the coordinates before sampling.
    pub transform: Option<UvTransform>,
}

impl TextureRef {
    /// Set 0 of `texture`, untransformed.
    pub fn new(texture: TextureId) -> Self {
        TextureRef { texture, uv_set: 0, transform: None }
    }
}

/// One channel of a texture read as a number.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Channel {
    /// Red.
    Red,
    /// Green.
    Green,
    /// Blue.
    Blue,
    /// Alpha (MTL's "matte", `-imfchan m`).
    #[default]
    Alpha,
    /// Rec. 709 luminance of red, green and blue (MTL's `-imfchan l`).
    Luminance,
}

/// A texture read as one number per texel, optionally remapped to `base + gain * value`
/// (MTL's `-mm base gain`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScalarTexture {
    /// The texture.
    pub texture: TextureRef,
    /// Which channel.
    pub channel: Channel,
    /// `base` and `gain`.
    pub remap: Option<[f32; 2]>,
}

/// What a normal-map texture encodes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NormalEncoding {
    /// Tangent-space normals, `rgb = (n + 1) / 2`, `+x` along the tangent (increasing `u`),
    /// `+y` along the bitangent (towards the top of the image), `+z` along the normal (glTF's
    /// `normalTexture`, MTL's `norm`).
    #[default]
    TangentSpace,
    /// A height field in one channel (MTL's `bump`): the normal tilts against the height's
    /// slope, where a rise of 1 from one texel to the next, times `scale`, is a 45-degree tilt.
    Height(Channel),
}

/// A normal or bump map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalMap {
    /// The texture.
    pub texture: TextureRef,
    /// glTF's `normalTexture.scale` (the tilt of the x and y components) or MTL's `-bm`.
    pub scale: f32,
    /// How the texels encode the normal.
    pub encoding: NormalEncoding,
}

/// Every texture slot of a material; `None` is "no texture", which multiplies by one.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MaterialTextures {
    /// Base colour (classic: the diffuse colour, MTL `map_Kd`), sRGB; its alpha is the
    /// coverage in glTF.
    pub base_color: Option<TextureRef>,
    /// glTF's metallic-roughness texture, linear: blue is metalness, green roughness.
    pub metallic_roughness: Option<TextureRef>,
    /// Normal or bump map, linear.
    pub normal: Option<NormalMap>,
    /// Emission colour, sRGB (glTF `emissiveTexture`, MTL `map_Ke`).
    pub emission: Option<TextureRef>,
    /// Coverage from a texture of its own (MTL `map_d`), linear.
    pub alpha: Option<ScalarTexture>,
    /// Highlight colour (MTL `map_Ks`), sRGB.
    pub specular: Option<TextureRef>,
    /// Ambient occlusion (glTF `occlusionTexture`: red channel, its `strength` as the remap
    /// `1 - strength + strength * red`), linear. A path tracer computes occlusion itself; the
    /// classic ambient term is what this approximates.
    pub occlusion: Option<ScalarTexture>,
}

impl MaterialTextures {
    /// Every texture the material uses, with the slot's name.
    pub fn slots(&self) -> Vec<(&'static str, TextureRef)> {
        let mut out = Vec::new();
        let mut push = |name, t: Option<TextureRef>| {
            if let Some(t) = t {
                out.push((name, t));
            }
        };
        push("base_color", self.base_color);
        push("metallic_roughness", self.metallic_roughness);
        push("normal", self.normal.map(|n| n.texture));
        push("emission", self.emission);
        push("alpha", self.alpha.map(|a| a.texture));
        push("specular", self.specular);
        push("occlusion", self.occlusion.map(|o| o.texture));
        out
    }

    /// True when no slot holds a texture.
    pub fn is_empty(&self) -> bool {
        // Asked at every hit: the slots are looked at in place rather than listed.
        let MaterialTextures { base_color, metallic_roughness, normal, emission, alpha, specular, occlusion } = self;
        base_color.is_none()
            && metallic_roughness.is_none()
            && normal.is_none()
            && emission.is_none()
            && alpha.is_none()
            && specular.is_none()
            && occlusion.is_none()
    }

    /// Every slot's reference, without a list allocated.
    pub(crate) fn refs(&self) -> [Option<&TextureRef>; 7] {
        let MaterialTextures { base_color, metallic_roughness, normal, emission, alpha, specular, occlusion } = self;
        [
            base_color.as_ref(),
            metallic_roughness.as_ref(),
            normal.as_ref().map(|n| &n.texture),
            emission.as_ref(),
            alpha.as_ref().map(|a| &a.texture),
            specular.as_ref(),
            occlusion.as_ref().map(|o| &o.texture),
        ]
    }

    /// Every reference with its texture index moved by `offset` (textures of a mesh file
    /// appended after the scene's).
    pub fn shifted(&self, offset: TextureId) -> Self {
        let mut t = self.clone();
        let refs = [
            t.base_color.as_mut(),
            t.metallic_roughness.as_mut(),
            t.normal.as_mut().map(|n| &mut n.texture),
            t.emission.as_mut(),
            t.alpha.as_mut().map(|a| &mut a.texture),
            t.specular.as_mut(),
            t.occlusion.as_mut().map(|o| &mut o.texture),
        ];
        for r in refs.into_iter().flatten() {
            r.texture += offset;
        }
        t
    }
}

/// How the coverage (alpha) of a surface is used (glTF 2.0 `alphaMode`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum AlphaMode {
    /// Alpha is ignored: the surface is solid.
    #[default]
    Opaque,
    /// Cut-out: where alpha is below `cutoff` there is no surface, elsewhere a solid one.
    Mask {
        /// glTF's `alphaCutoff`, 0.5 by default.
        cutoff: f32,
    },
    /// Partial coverage: a fraction `alpha` of the surface is there.
    Blend,
}

/// Coverage: the mode and the constant factor (glTF's base colour factor alpha, MTL's `d`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Alpha {
    /// The mode.
    pub mode: AlphaMode,
    /// Multiplies the texture's alpha, in `0..=1`.
    pub factor: f32,
}

impl Default for Alpha {
    fn default() -> Self {
        Alpha { mode: AlphaMode::Opaque, factor: 1.0 }
    }
}

/// Surface appearance. The first seven fields are the classic model's, with the meanings
/// [`MaterialModel`] gives them for each model.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Diffuse (Lambert) colour; the base colour factor under metallic-roughness.
    pub diffuse: Vec3,
    /// Specular highlight colour (Blinn-Phong).
    pub specular: Vec3,
    /// Blinn-Phong exponent.
    pub shininess: f32,
    /// Fraction of light mirrored, in `0..=1`.
    pub reflectivity: f32,
    /// Fraction of light transmitted, in `0..=1`; `reflectivity + transparency <= 1`.
    pub transparency: f32,
    /// Index of refraction of the inside of a transparent object (and of the dielectric of the
    /// metallic-roughness model).
    pub ior: f32,
    /// Light emitted by the surface itself (linear RGB radiance, any emissive strength applied).
    pub emission: Vec3,
    /// Which model the fields follow.
    pub model: MaterialModel,
    /// Texture slots.
    pub textures: MaterialTextures,
    /// Coverage.
    pub alpha: Alpha,
    /// Whether the back face is the same surface as the front (true: shade both sides alike, as
    /// the classic model always did). glTF's `doubleSided: false` makes it false: the file says
    /// a viewer may cull back faces, and its normals are meant for the front only.
    pub double_sided: bool,
}

impl Default for Material {
    /// A matte light grey.
    fn default() -> Self {
        Material {
            diffuse: Vec3::splat(0.7),
            specular: Vec3::ZERO,
            shininess: 32.0,
            reflectivity: 0.0,
            transparency: 0.0,
            ior: 1.5,
            emission: Vec3::ZERO,
            model: MaterialModel::Classic,
            textures: MaterialTextures::default(),
            alpha: Alpha::default(),
            double_sided: true,
        }
    }
}

impl Material {
    /// A metallic-roughness material with the given base colour, metalness and roughness, and
    /// glTF's other defaults (index 1.5, no emission, opaque, single-sided).
    pub fn metallic_roughness(base_color: Vec3, metallic: f32, roughness: f32) -> Self {
        Material {
            diffuse: base_color,
            model: MaterialModel::MetallicRoughness { metallic, roughness, transmission: 0.0 },
            double_sided: false,
            ..Material::default()
        }
    }

    /// True when some rays may pass through the surface for its coverage (alpha mode `MASK` or
    /// `BLEND`), so that queries need the coverage test of [`Material::passes_through`].
    pub fn has_cutouts(&self) -> bool {
        self.alpha.mode != AlphaMode::Opaque
    }

    /// True when rays ignore the back faces of the material's triangles (the side against their
    /// winding's normal): single-sided materials (glTF `doubleSided: false`) that transmit no
    /// light. A transmitting one keeps its back faces, since light leaves its inside through
    /// them.
    pub fn culls_back_faces(&self) -> bool {
        let transmits =
            matches!(self.model, MaterialModel::MetallicRoughness { transmission, .. } if transmission > 0.0);
        !self.double_sided && !transmits && self.transparency <= 0.0
    }
}

/// Perceptual roughness (`sqrt(alpha)`) equivalent to a Blinn-Phong exponent: the
/// Beckmann/GGX width with the same peak, `alpha = sqrt(2 / (n + 2))` (Walter, Marschner, Li and
/// Torrance 2007, section 5.2).
pub fn shininess_to_roughness(shininess: f32) -> f32 {
    (2.0 / (shininess.max(0.0) + 2.0)).sqrt().sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uv_transform_follows_the_extension() {
        // KHR_texture_transform's example: offset [0.5, 0], rotation pi/2, scale [2, 2] maps
        // (1, 0) through scale (2, 0), rotation (0, -2), offset (0.5, -2).
        let t =
            UvTransform { offset: Vec2::new(0.5, 0.0), rotation: std::f32::consts::FRAC_PI_2, scale: Vec2::splat(2.0) };
        assert!((t.apply(Vec2::X) - Vec2::new(0.5, -2.0)).length() < 1e-6);
        assert!((t.apply(Vec2::Y) - Vec2::new(2.5, 0.0)).length() < 1e-6);
        assert_eq!(UvTransform::default().apply(Vec2::new(0.3, 0.7)), Vec2::new(0.3, 0.7));
    }

    #[test]
    fn defaults_are_the_classic_model() {
        let m = Material::default();
        assert_eq!((m.model, m.alpha, m.double_sided), (MaterialModel::Classic, Alpha::default(), true));
        assert!(m.textures.is_empty() && !m.has_cutouts());
    }

    #[test]
    fn shininess_to_roughness_by_hand() {
        // n = 2: alpha = sqrt(2 / 4), roughness = alpha^(1/2) = 0.5^(1/4).
        assert!((shininess_to_roughness(2.0) - 0.5f32.powf(0.25)).abs() < 1e-6);
        assert_eq!(shininess_to_roughness(0.0), 1.0);
        assert!(shininess_to_roughness(1e6) < 0.04);
    }

    #[test]
    fn texture_slots_shift_together() {
        let t = MaterialTextures {
            base_color: Some(TextureRef::new(0)),
            normal: Some(NormalMap { texture: TextureRef::new(2), scale: 1.0, encoding: NormalEncoding::TangentSpace }),
            ..Default::default()
        };
        let s = t.shifted(5);
        assert_eq!(
            s.slots().iter().map(|(n, r)| (*n, r.texture)).collect::<Vec<_>>(),
            [("base_color", 5), ("normal", 7)]
        );
    }
}
