//! A texture of the scene: an image (decoded once, shared through an `Arc` by every texture and
//! material that uses it) with the sampler that reads it, and where it came from. A texture whose
//! image could not be read keeps the reason; it samples as `None`, and each material slot then
//! shows its own fallback (see [`crate::material`]).

use std::path::PathBuf;
use std::sync::Arc;

use glam::{Vec2, Vec4};

use super::filtered::{UvFootprint, sample_footprint};
use super::image::{ColorSpace, TexelImage};
use super::mip::MipCache;
use super::sampler::Sampler;

/// Index into [`crate::Scene::textures`] (or, in a [`crate::mesh::LoadedMesh`], into its own
/// `textures`).
pub type TextureId = u32;

/// Where a texture's image came from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TextureSource {
    /// A file (a glTF image URI, an MTL map, a scene's texture key), resolved against the file
    /// that named it.
    File(PathBuf),
    /// Bytes inside the mesh file (a glTF buffer view or a `data:` URI), described for people,
    /// such as `images[2] (bufferView 5)`.
    Embedded(String),
}

impl std::fmt::Display for TextureSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TextureSource::File(p) => write!(f, "{}", p.display()),
            TextureSource::Embedded(what) => write!(f, "{what} (embedded)"),
        }
    }
}

/// A texture: an image and its sampler.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Its name for people (the glTF texture's or image's name, else the file name).
    pub name: String,
    /// Where the image came from.
    pub source: TextureSource,
    /// How it is read.
    pub sampler: Sampler,
    /// The decoded image, or `None` when it could not be read.
    pub image: Option<Arc<TexelImage>>,
    /// Why the image could not be read.
    pub error: Option<String>,
    /// The image's mip pyramids, built when a footprint first needs them.
    pub mips: MipCache,
}

impl Texture {
    /// A readable texture.
    pub fn new(name: impl Into<String>, source: TextureSource, sampler: Sampler, image: Arc<TexelImage>) -> Self {
        Texture { name: name.into(), source, sampler, image: Some(image), error: None, mips: MipCache::default() }
    }

    /// A texture whose image could not be read, and why.
    pub fn unreadable(name: impl Into<String>, source: TextureSource, sampler: Sampler, error: String) -> Self {
        Texture { name: name.into(), source, sampler, image: None, error: Some(error), mips: MipCache::default() }
    }

    /// The filtered value at `uv` (glTF convention: `(0, 0)` the image's top-left corner, `v`
    /// down), linear RGBA with the colour channels decoded from `space`; `None` when the image
    /// could not be read.
    #[inline]
    pub fn sample(&self, uv: Vec2, space: ColorSpace) -> Option<Vec4> {
        self.image.as_ref().map(|image| self.sampler.sample(image, uv, space))
    }

    /// The value over `footprint` centred at `uv` (see [`super::filtered`]); without a
    /// footprint, [`Texture::sample`]. `None` when the image could not be read.
    #[inline]
    pub fn sample_over(&self, uv: Vec2, footprint: Option<UvFootprint>, space: ColorSpace) -> Option<Vec4> {
        let image = self.image.as_ref()?;
        Some(match footprint {
            None => self.sampler.sample(image, uv, space),
            Some(f) => sample_footprint(&self.sampler, image, || self.mips.get(image, space), uv, f, space),
        })
    }

    /// `width x height` for people, or `unreadable`.
    pub fn size_text(&self) -> String {
        match &self.image {
            Some(i) => format!("{}x{}", i.width(), i.height()),
            None => "unreadable".into(),
        }
    }
}
