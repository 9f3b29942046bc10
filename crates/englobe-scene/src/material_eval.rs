//! The one place where a material meets its textures: [`Material::evaluate`] gives the numbers a
//! BSDF needs at one texture coordinate, [`Material::coverage`] and
//! [`Material::passes_through`] what an any-hit or closest-hit query needs to skip cut-out or
//! partly covered surfaces.
//!
//! glTF 2.0 (section 3.9.2) multiplies each factor by its texture: base colour and alpha by the
//! base colour texture (sRGB colour, linear alpha), roughness by the green and metalness by the
//! blue channel of the metallic-roughness texture, emission by the emissive texture (sRGB). The
//! normal texture gives `normalize((2 * rgb - 1) * (scale, scale, 1))` in tangent space. The
//! classic model reads its textures the same way (MTL `map_Kd` scales `diffuse`, `map_Ks`
//! `specular`, `map_Ke` `emission`, `map_d` the coverage).
//!
//! Every texture reads the texture coordinate set its reference names (see
//! [`crate::tex_coords`]); the coverage tests read the alpha or base colour texture's set.
//!
//! A texture that could not be read shows a fallback that makes the fault visible where it is
//! colour and harmless where it is data: magenta base colour; no emission; factors unchanged for
//! metalness, roughness, alpha and highlight; the interpolated normal.

use std::sync::Arc;

use glam::{Vec2, Vec3, Vec4};

use crate::material::{
    AlphaMode, Channel, Material, MaterialModel, NormalEncoding, ScalarTexture, TextureRef, shininess_to_roughness,
};
use crate::tex_coords::TexCoords;
use crate::texture::{ColorSpace, Texture, UvFootprint};

/// Base colour shown where a base colour texture could not be read.
pub const MISSING_TEXTURE_COLOR: Vec3 = Vec3::new(1.0, 0.0, 1.0);

/// What a material shows in place of an unreadable texture in `slot` (as loaders name slots in
/// warnings: "base colour", "normal", ...).
pub(crate) fn fallback_text(slot: &str) -> &'static str {
    match slot {
        "base colour" => "the surface shows magenta there",
        "emission" => "the surface does not glow",
        "normal" | "bump" => "the interpolated normal is used",
        "alpha" => "the surface is opaque",
        _ => "the material's factors are used alone",
    }
}

/// The parameters of a surface at one point, textures applied.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceParams {
    /// Linear base colour (classic: the diffuse colour).
    pub base_color: Vec3,
    /// Coverage in `0..=1` (1 for opaque materials).
    pub alpha: f32,
    /// Metalness in `0..=1` (0 for classic materials).
    pub metallic: f32,
    /// Perceptual roughness in `0..=1` (classic: [`shininess_to_roughness`] of the shininess).
    pub roughness: f32,
    /// Share of the dielectric base that transmits (classic: `transparency`).
    pub transmission: f32,
    /// Index of refraction.
    pub ior: f32,
    /// Emitted radiance.
    pub emission: Vec3,
    /// The unit normal in tangent space from the normal or bump map (`x` along the tangent, `y`
    /// along the bitangent, `z` along the interpolated normal), or `None` without a readable
    /// map or texture coordinates.
    pub normal_ts: Option<Vec3>,
    /// Highlight colour: classic `specular` (times `map_Ks`); under metallic-roughness the
    /// dielectric's specular colour factor, 1 (englobe does not read `KHR_materials_specular`).
    pub specular: Vec3,
    /// Ambient occlusion in `0..=1` from the occlusion texture (1 without one): for ambient
    /// terms only, never for light that is traced.
    pub occlusion: f32,
}

/// The texture of `r` at `uv`, over `footprint` when there is one (moved by the texture
/// transform's linear part, as the coordinates are).
fn lookup_over(
    textures: &[Arc<Texture>],
    r: &TextureRef,
    uv: Vec2,
    footprint: Option<UvFootprint>,
    space: ColorSpace,
) -> Option<Vec4> {
    let (uv, footprint) = match r.transform {
        None => (uv, footprint),
        Some(t) => (t.apply(uv), footprint.map(|f| f.mapped(|a| t.apply(a) - t.apply(Vec2::ZERO)))),
    };
    textures.get(r.texture as usize)?.sample_over(uv, footprint, space)
}

fn channel(v: Vec4, c: Channel) -> f32 {
    match c {
        Channel::Red => v.x,
        Channel::Green => v.y,
        Channel::Blue => v.z,
        Channel::Alpha => v.w,
        Channel::Luminance => 0.2126 * v.x + 0.7152 * v.y + 0.0722 * v.z,
    }
}

/// The texture of `r` at the coordinates of its set in `at`; `None` where the point has none.
fn lookup_at(textures: &[Arc<Texture>], r: &TextureRef, at: &TexCoords, space: ColorSpace) -> Option<Option<Vec4>> {
    let (uv, footprint) = at.of(r);
    Some(lookup_over(textures, r, uv?, footprint, space))
}

fn scalar(textures: &[Arc<Texture>], s: &ScalarTexture, at: &TexCoords) -> Option<f32> {
    let v = channel(lookup_at(textures, &s.texture, at, ColorSpace::Linear)??, s.channel);
    Some(s.remap.map_or(v, |[base, gain]| base + gain * v))
}

impl Material {
    /// The surface parameters at texture coordinate `uv` (glTF convention; `None` when the
    /// mesh has none, which leaves the factors alone), read by every texture whatever its set,
    /// reading `textures` (the scene's).
    pub fn evaluate(&self, textures: &[Arc<Texture>], uv: Option<Vec2>) -> SurfaceParams {
        self.evaluate_at(textures, &TexCoords::one(uv, None))
    }

    /// [`Material::evaluate`] with every texture read over `footprint` around `uv` (a ray
    /// cone's, see [`crate::texture::sample_footprint`]); `None` reads them at the point, exactly
    /// as `evaluate` does.
    pub fn evaluate_over(
        &self,
        textures: &[Arc<Texture>],
        uv: Option<Vec2>,
        footprint: Option<UvFootprint>,
    ) -> SurfaceParams {
        self.evaluate_at(textures, &TexCoords::one(uv, footprint))
    }

    /// The surface parameters at the point whose coordinates (and footprints) in each texture
    /// coordinate set are `at`: every texture reads its own set.
    pub fn evaluate_at(&self, textures: &[Arc<Texture>], at: &TexCoords) -> SurfaceParams {
        let t = &self.textures;
        let sample = |r: &Option<TextureRef>, space| lookup_at(textures, r.as_ref()?, at, space);
        // Some(None): the slot has a texture that could not be read.
        let base = sample(&t.base_color, ColorSpace::Srgb);
        let base_color = match base {
            Some(Some(c)) => self.diffuse * c.truncate(),
            Some(None) => MISSING_TEXTURE_COLOR,
            None => self.diffuse,
        };
        let emission = match sample(&t.emission, ColorSpace::Srgb) {
            Some(Some(c)) => self.emission * c.truncate(),
            Some(None) => Vec3::ZERO,
            None => self.emission,
        };
        let (metallic, roughness, transmission, specular) = match self.model {
            MaterialModel::Classic => {
                let specular = match sample(&t.specular, ColorSpace::Srgb) {
                    Some(Some(c)) => self.specular * c.truncate(),
                    _ => self.specular,
                };
                (0.0, shininess_to_roughness(self.shininess), self.transparency, specular)
            }
            MaterialModel::MetallicRoughness { metallic, roughness, transmission } => {
                match sample(&t.metallic_roughness, ColorSpace::Linear) {
                    Some(Some(mr)) => (metallic * mr.z, roughness * mr.y, transmission, Vec3::ONE),
                    _ => (metallic, roughness, transmission, Vec3::ONE),
                }
            }
            // The path tracer reads these models' own parameters; the numbers here are what the
            // classic fields say, for the integrators that only know those.
            MaterialModel::Conductor { .. }
            | MaterialModel::Dielectric { .. }
            | MaterialModel::CoatedDiffuse { .. } => {
                (0.0, shininess_to_roughness(self.shininess), self.transparency, self.specular)
            }
        };
        let normal_ts = t.normal.and_then(|n| self.normal_from_map(textures, &n, at));
        SurfaceParams {
            base_color,
            alpha: self.alpha_at(textures, at, base),
            metallic: metallic.clamp(0.0, 1.0),
            roughness: roughness.clamp(0.0, 1.0),
            transmission: transmission.clamp(0.0, 1.0),
            ior: self.ior,
            emission,
            normal_ts,
            specular,
            occlusion: t.occlusion.as_ref().and_then(|o| scalar(textures, o, at)).unwrap_or(1.0).clamp(0.0, 1.0),
        }
    }

    /// The alpha at `at`: the factor times the alpha texture's value when there is one (MTL),
    /// else times the base colour texture's alpha (glTF), each read in its own set. `base` is
    /// the base colour sample when the caller already has it.
    fn alpha_at(&self, textures: &[Arc<Texture>], at: &TexCoords, base: Option<Option<Vec4>>) -> f32 {
        if self.alpha.mode == AlphaMode::Opaque {
            return 1.0;
        }
        let texture = match &self.textures.alpha {
            Some(a) => scalar(textures, a, at),
            None => base
                .or_else(|| lookup_at(textures, self.textures.base_color.as_ref()?, at, ColorSpace::Linear))
                .flatten()
                .map(|c| c.w),
        };
        (self.alpha.factor * texture.unwrap_or(1.0)).clamp(0.0, 1.0)
    }

    /// The fraction of the surface present at `uv` (one coordinate for every set, or a
    /// [`TexCoords`]): 1 for opaque materials; 0 or 1 for `MASK` (against the cutoff); the
    /// alpha itself for `BLEND`.
    pub fn coverage(&self, textures: &[Arc<Texture>], uv: impl Into<TexCoords>) -> f32 {
        let at = uv.into();
        match self.alpha.mode {
            AlphaMode::Opaque => 1.0,
            AlphaMode::Mask { cutoff } => {
                if self.alpha_at(textures, &at, None) >= cutoff {
                    1.0
                } else {
                    0.0
                }
            }
            AlphaMode::Blend => self.alpha_at(textures, &at, None),
        }
    }

    /// Whether a ray passes through the surface at `uv`, for a number `xi` uniform in `0..1`:
    /// `xi >= coverage`. A `MASK` surface is passed through exactly where it is cut out, for any
    /// `xi`; a `BLEND` surface with probability `1 - alpha` (stochastic transparency, Enderton,
    /// Sintorn, Shirley and Luebke 2010). For closest-hit and any-hit queries to agree, `xi` must
    /// depend only on the ray and the hit (a hash of them), not on which query asks.
    pub fn passes_through(&self, textures: &[Arc<Texture>], uv: impl Into<TexCoords>, xi: f32) -> bool {
        self.alpha.mode != AlphaMode::Opaque && xi >= self.coverage(textures, uv)
    }

    /// True where a `MASK` surface is cut out (or a `BLEND` one fully transparent).
    pub fn is_cut_out(&self, textures: &[Arc<Texture>], uv: impl Into<TexCoords>) -> bool {
        self.alpha.mode != AlphaMode::Opaque && self.coverage(textures, uv) <= 0.0
    }

    fn normal_from_map(
        &self,
        textures: &[Arc<Texture>],
        n: &crate::material::NormalMap,
        at: &TexCoords,
    ) -> Option<Vec3> {
        let (uv, footprint) = at.of(&n.texture);
        let uv = uv?;
        match n.encoding {
            // A filtered normal map averages normals; the average is shorter than one where
            // they disagree, and is normalised like any other.
            NormalEncoding::TangentSpace => {
                let c = lookup_over(textures, &n.texture, uv, footprint, ColorSpace::Linear)?.truncate();
                ((c * 2.0 - Vec3::ONE) * Vec3::new(n.scale, n.scale, 1.0)).try_normalize()
            }
            NormalEncoding::Height(ch) => {
                let tex = textures.get(n.texture.texture as usize)?;
                let image = tex.image.as_ref()?;
                let (du, dv) = (1.0 / image.width() as f32, 1.0 / image.height() as f32);
                let h = |d: Vec2| -> Option<f32> {
                    let uv = n.texture.transform.map_or(uv, |t| t.apply(uv)) + d;
                    Some(channel(tex.sample(uv, ColorSpace::Linear)?, ch))
                };
                // Slopes per texel along +u and towards the top of the image (-v).
                let gx = (h(Vec2::new(du, 0.0))? - h(Vec2::new(-du, 0.0))?) * 0.5;
                let gy = (h(Vec2::new(0.0, -dv))? - h(Vec2::new(0.0, dv))?) * 0.5;
                Vec3::new(-n.scale * gx, -n.scale * gy, 1.0).try_normalize()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::{Alpha, NormalMap};
    use crate::texture::{Sampler, TexelImage, TextureSource};

    fn texture(w: u32, h: u32, texels: Vec<[u8; 4]>) -> Arc<Texture> {
        let img = Arc::new(TexelImage::from_rgba8(w, h, texels).unwrap());
        Arc::new(Texture::new("t", TextureSource::Embedded("test".into()), Sampler::default(), img))
    }

    fn broken() -> Arc<Texture> {
        Arc::new(Texture::unreadable("b", TextureSource::File("b.png".into()), Sampler::default(), "gone".into()))
    }

    #[test]
    fn base_colour_metal_and_roughness_by_hand() {
        // One texel: sRGB 188 (linear 0.5029) red, green 128 (roughness), blue 64 (metal), alpha 51.
        let textures = vec![texture(1, 1, vec![[188, 128, 64, 51]])];
        let mut m = Material::metallic_roughness(Vec3::new(0.5, 1.0, 1.0), 1.0, 0.5);
        m.textures.base_color = Some(TextureRef::new(0));
        m.textures.metallic_roughness = Some(TextureRef::new(0));
        m.textures.occlusion =
            Some(ScalarTexture { texture: TextureRef::new(0), channel: Channel::Red, remap: Some([0.2, 0.8]) });
        let p = m.evaluate(&textures, Some(Vec2::new(0.3, 0.6)));
        assert!((p.base_color.x - 0.5 * 0.5029).abs() < 1e-3, "{p:?}");
        assert!((p.occlusion - (0.2 + 0.8 * 188.0 / 255.0)).abs() < 1e-6, "strength 0.8");
        assert!((p.base_color.y - crate::texture::srgb_to_linear(128.0 / 255.0)).abs() < 1e-6);
        assert!((p.metallic - 64.0 / 255.0).abs() < 1e-6 && (p.roughness - 0.5 * 128.0 / 255.0).abs() < 1e-6);
        assert_eq!(p.alpha, 1.0, "opaque ignores alpha");
        assert_eq!(p.specular, Vec3::ONE);
        // Without texture coordinates the factors stand alone.
        let p = m.evaluate(&textures, None);
        assert_eq!((p.base_color, p.metallic, p.roughness), (Vec3::new(0.5, 1.0, 1.0), 1.0, 0.5));
    }

    #[test]
    fn alpha_modes() {
        let textures = vec![texture(2, 1, vec![[255, 255, 255, 0], [255, 255, 255, 255]])];
        let clamp = |mut m: Material| {
            m.textures.base_color = Some(TextureRef::new(0));
            m
        };
        let left = Some(Vec2::new(0.25, 0.5));
        let right = Some(Vec2::new(0.75, 0.5));
        let mid = Some(Vec2::new(0.5, 0.5));
        let mask = clamp(Material {
            alpha: Alpha { mode: AlphaMode::Mask { cutoff: 0.5 }, factor: 1.0 },
            ..Material::default()
        });
        assert!(mask.is_cut_out(&textures, left) && !mask.is_cut_out(&textures, right));
        assert!(mask.passes_through(&textures, left, 0.0) && !mask.passes_through(&textures, right, 0.999));
        // The bilinear middle has alpha 0.5: at the cutoff, kept.
        assert_eq!(mask.coverage(&textures, mid), 1.0);
        let blend = clamp(Material { alpha: Alpha { mode: AlphaMode::Blend, factor: 0.8 }, ..Material::default() });
        assert!((blend.coverage(&textures, mid) - 0.4).abs() < 1e-6);
        assert!(blend.passes_through(&textures, mid, 0.41) && !blend.passes_through(&textures, mid, 0.39));
        let opaque = clamp(Material::default());
        assert!(!opaque.passes_through(&textures, left, 0.99) && opaque.coverage(&textures, left) == 1.0);
        // An alpha texture of its own (MTL map_d) wins over the base colour's alpha.
        let mut d = blend.clone();
        d.textures.alpha = Some(ScalarTexture { texture: TextureRef::new(1), channel: Channel::Red, remap: None });
        let textures2 = vec![textures[0].clone(), texture(1, 1, vec![[128, 0, 0, 255]])];
        assert!((d.coverage(&textures2, left) - 0.8 * 128.0 / 255.0).abs() < 1e-6);
    }

    #[test]
    fn normal_maps_decode_with_scale() {
        // rgb (255, 128, 255): n = (1, 0.0039, 1) before normalising; scale 0.5 halves x and y.
        let textures = vec![texture(1, 1, vec![[255, 128, 255, 255]])];
        let mut m = Material::default();
        m.textures.normal =
            Some(NormalMap { texture: TextureRef::new(0), scale: 0.5, encoding: NormalEncoding::TangentSpace });
        let n = m.evaluate(&textures, Some(Vec2::ZERO)).normal_ts.unwrap();
        let y = 2.0 * 128.0 / 255.0 - 1.0;
        let want = Vec3::new(0.5, 0.5 * y, 1.0).normalize();
        assert!((n - want).length() < 1e-6, "{n} {want}");
        assert_eq!(m.evaluate(&textures, None).normal_ts, None);
    }

    #[test]
    fn height_maps_tilt_against_the_slope() {
        // Heights rising by 0.2 per texel along u, flat along v (4 x 4, repeat would wrap: clamp).
        let texels = (0..4).flat_map(|_| (0..4).map(|i| [(i * 51) as u8, 0, 0, 255])).collect();
        let img = Arc::new(TexelImage::from_rgba8(4, 4, texels).unwrap());
        let s = Sampler::wrapping(crate::texture::Wrap::ClampToEdge);
        let textures = vec![Arc::new(Texture::new("h", TextureSource::Embedded("h".into()), s, img))];
        let mut m = Material::default();
        m.textures.normal =
            Some(NormalMap { texture: TextureRef::new(0), scale: 1.0, encoding: NormalEncoding::Height(Channel::Red) });
        let n = m.evaluate(&textures, Some(Vec2::new(0.5, 0.5))).normal_ts.unwrap();
        assert!((n - Vec3::new(-0.2, 0.0, 1.0).normalize()).length() < 1e-5, "{n}");
    }

    #[test]
    fn unreadable_textures_fall_back() {
        let textures = vec![broken()];
        let mut m = Material::metallic_roughness(Vec3::splat(0.8), 0.3, 0.7);
        m.emission = Vec3::ONE;
        m.textures.base_color = Some(TextureRef::new(0));
        m.textures.metallic_roughness = Some(TextureRef::new(0));
        m.textures.emission = Some(TextureRef::new(0));
        m.textures.normal =
            Some(NormalMap { texture: TextureRef::new(0), scale: 1.0, encoding: NormalEncoding::TangentSpace });
        m.alpha = Alpha { mode: AlphaMode::Mask { cutoff: 0.5 }, factor: 1.0 };
        let p = m.evaluate(&textures, Some(Vec2::ZERO));
        assert_eq!(p.base_color, MISSING_TEXTURE_COLOR);
        assert_eq!((p.metallic, p.roughness, p.emission, p.normal_ts, p.alpha), (0.3, 0.7, Vec3::ZERO, None, 1.0));
        // A reference past the end of the list reads as unreadable too.
        m.textures.base_color = Some(TextureRef::new(9));
        assert_eq!(m.evaluate(&textures, Some(Vec2::ZERO)).base_color, MISSING_TEXTURE_COLOR);
    }

    #[test]
    fn classic_keeps_its_meaning() {
        let m = Material {
            diffuse: Vec3::new(0.1, 0.2, 0.3),
            specular: Vec3::splat(0.5),
            transparency: 0.25,
            ..Material::default()
        };
        let p = m.evaluate(&[], Some(Vec2::ZERO));
        assert_eq!((p.base_color, p.specular, p.transmission, p.metallic), (m.diffuse, m.specular, 0.25, 0.0));
        assert!((p.roughness - shininess_to_roughness(32.0)).abs() < 1e-7);
    }
}
