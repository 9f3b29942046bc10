//! Textures: images decoded once per scene (PNG and JPEG through the `image` crate, sizes checked
//! before anything is allocated), shared by every material that names them, and sampled with
//! bilinear filtering and the wrap modes of the glTF 2.0 sampler, or over a ray cone's footprint
//! through a mip pyramid (see `filtered`).
//!
//! Coordinates follow glTF 2.0 (section 3.9.3, "Texture coordinates"): `(0, 0)` is the top-left
//! corner of the image (the first texel of its first row), `u` grows to the right and `v`
//! downwards. Loaders of formats with the other convention (OBJ, PLY: `v` up from the bottom)
//! flip `v` when they read the coordinates, so every texture coordinate of a [`crate::Scene`]
//! is in this one convention.

mod decode;
mod filtered;
mod image;
mod mip;
mod sampler;
mod scene_texture;
mod srgb;

pub use decode::{MAX_TEXTURE_FILE_BYTES, MAX_TEXTURE_PIXELS, TextureError, TextureLoader, decode_image};
pub use filtered::{FilterPlan, MAX_ANISOTROPY, UvFootprint, sample_footprint};
pub use image::{ColorSpace, TexelImage, Texels};
pub use mip::{MipCache, MipLevel, MipPyramid};
pub use sampler::{Filter, Sampler, Wrap};
pub use scene_texture::{Texture, TextureId, TextureSource};
pub use srgb::{linear_to_srgb, srgb_to_linear};
