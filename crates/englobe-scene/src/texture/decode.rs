//! Decoding images: PNG and JPEG (and OpenEXR) through the `image` crate, with the size refused
//! before the texels are allocated (`image::Limits` checks the header's width and height, and
//! every allocation the decoder makes), and a cache so that an image named by several textures
//! or materials is read and decoded once.

use std::collections::HashMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use image::DynamicImage;

use super::image::{TexelImage, Texels};
use crate::mesh::{guarded, read_limited};

/// Largest texture file read.
pub const MAX_TEXTURE_FILE_BYTES: u64 = 256 << 20;
/// Most texels one texture may have (an 8192 x 8192 image; 256 MiB in 8-bit RGBA).
pub const MAX_TEXTURE_PIXELS: u64 = 1 << 26;
/// Widest and tallest texture.
const MAX_TEXTURE_SIDE: u32 = 1 << 15;

/// Why an image could not be used, as a sentence for a warning.
pub type TextureError = String;

/// Decodes `bytes` (PNG, JPEG or OpenEXR, recognised by their first bytes), refusing images over
/// [`MAX_TEXTURE_PIXELS`] before decoding them.
pub fn decode_image(bytes: &[u8]) -> Result<TexelImage, TextureError> {
    let reader = image::ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| format!("cannot read the image: {e}"))?;
    let Some(format) = reader.format() else {
        return Err("not an image englobe reads (expected PNG or JPEG)".into());
    };
    let mut reader = reader;
    reader.limits(limits());
    let (width, height) = reader.into_dimensions().map_err(|e| format!("cannot read the {format:?} header: {e}"))?;
    if width as u64 * height as u64 > MAX_TEXTURE_PIXELS {
        return Err(format!("a {width}x{height} image is over the limit of {MAX_TEXTURE_PIXELS} texels"));
    }
    // The dimensions consumed the reader; the header is read again (it is small).
    let mut reader = image::ImageReader::with_format(Cursor::new(bytes), format);
    reader.limits(limits());
    let decoded = guarded(Path::new(""), "image", || reader.decode())
        .map_err(|_| format!("the {format:?} decoder failed on this image"))?
        .map_err(|e| format!("cannot decode the {format:?} image: {e}"))?;
    let channels = decoded.color().channel_count();
    let (w, h) = (decoded.width(), decoded.height());
    let texels = match decoded {
        DynamicImage::ImageLuma16(_)
        | DynamicImage::ImageLumaA16(_)
        | DynamicImage::ImageRgb16(_)
        | DynamicImage::ImageRgba16(_) => Texels::Rgba16(decoded.into_rgba16().pixels().map(|p| p.0).collect()),
        DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_) => {
            Texels::RgbaF32(decoded.into_rgba32f().pixels().map(|p| p.0).collect())
        }
        other => Texels::Rgba8(rgba8(other)),
    };
    TexelImage::new(w, h, channels, texels).ok_or_else(|| format!("the decoder returned an empty {w}x{h} image"))
}

/// The decoder's limits: the sides, and room for the decoded image in its own format and the
/// RGBA copy, at 16 bits a channel.
fn limits() -> image::Limits {
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_TEXTURE_SIDE);
    limits.max_image_height = Some(MAX_TEXTURE_SIDE);
    limits.max_alloc = Some(MAX_TEXTURE_PIXELS * 8 * 2);
    limits
}

/// The texels of an 8-bit image as `[r, g, b, a]`, without a second copy when it already is RGBA.
fn rgba8(image: DynamicImage) -> Vec<[u8; 4]> {
    let raw = image.into_rgba8().into_raw();
    raw.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect()
}

/// Images read so far, by file or by a key naming embedded bytes, with their errors: each is
/// decoded once however many textures use it.
#[derive(Default)]
pub struct TextureLoader {
    files: HashMap<PathBuf, Result<Arc<TexelImage>, TextureError>>,
    embedded: HashMap<String, Result<Arc<TexelImage>, TextureError>>,
}

impl TextureLoader {
    /// The image in the file `path`.
    pub fn file(&mut self, path: &Path) -> Result<Arc<TexelImage>, TextureError> {
        let key = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_owned());
        self.files
            .entry(key)
            .or_insert_with(|| {
                let bytes = read_limited(path, MAX_TEXTURE_FILE_BYTES).map_err(|e| e.kind.to_string())?;
                decode_image(&bytes).map(Arc::new)
            })
            .clone()
    }

    /// The image in `bytes`, cached under `key` (which must name the bytes uniquely within one
    /// loader, such as `images[3]`).
    pub fn embedded(
        &mut self,
        key: &str,
        bytes: impl FnOnce() -> Result<Vec<u8>, TextureError>,
    ) -> Result<Arc<TexelImage>, TextureError> {
        if let Some(done) = self.embedded.get(key) {
            return done.clone();
        }
        let result = bytes().and_then(|b| decode_image(&b).map(Arc::new));
        self.embedded.insert(key.to_owned(), result.clone());
        result
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A PNG of `width` x `height` RGBA texels.
    pub(crate) fn png(width: u32, height: u32, texels: &[[u8; 4]]) -> Vec<u8> {
        let flat: Vec<u8> = texels.iter().flatten().copied().collect();
        let img = image::RgbaImage::from_raw(width, height, flat).unwrap();
        let mut out = Cursor::new(Vec::new());
        img.write_to(&mut out, image::ImageFormat::Png).unwrap();
        out.into_inner()
    }

    #[test]
    fn png_round_trip_and_grey_jpeg() {
        let texels = [[188, 0, 0, 255], [0, 255, 0, 128], [1, 2, 3, 4], [9, 9, 9, 9]];
        let img = decode_image(&png(2, 2, &texels)).unwrap();
        assert_eq!((img.width(), img.height(), img.channels(), img.bits()), (2, 2, 4, 8));
        let px = img.fetch(1, 0, super::super::ColorSpace::Linear);
        assert_eq!(px, glam::Vec4::new(0.0, 1.0, 0.0, 128.0 / 255.0));
        // A grey JPEG: one channel, copied to red, green and blue.
        let grey = image::GrayImage::from_pixel(8, 8, image::Luma([200]));
        let mut jpeg = Cursor::new(Vec::new());
        grey.write_to(&mut jpeg, image::ImageFormat::Jpeg).unwrap();
        let img = decode_image(&jpeg.into_inner()).unwrap();
        assert_eq!(img.channels(), 1);
        let px = img.fetch(3, 3, super::super::ColorSpace::Linear);
        assert!((px.x - 200.0 / 255.0).abs() < 3.0 / 255.0 && px.x == px.y && px.y == px.z && px.w == 1.0, "{px}");
    }

    #[test]
    fn bad_images_are_errors_not_panics() {
        assert!(decode_image(b"not an image at all").is_err());
        let mut cut = png(4, 4, &[[7; 4]; 16]);
        cut.truncate(cut.len() / 2);
        assert!(decode_image(&cut).is_err());
        // A valid PNG header (its checksum made right) claiming 2^14 x 2^14 texels, within each
        // side's limit but over the texel limit, is refused before a texel is decoded.
        let mut huge = png(1, 1, &[[0; 4]]);
        huge[16..20].copy_from_slice(&(1u32 << 14).to_be_bytes());
        huge[20..24].copy_from_slice(&(1u32 << 14).to_be_bytes());
        let crc = crc32(&huge[12..29]);
        huge[29..33].copy_from_slice(&crc.to_be_bytes());
        let e = decode_image(&huge).unwrap_err();
        assert!(e.contains("16384x16384") && e.contains("over the limit"), "{e}");
        // Wider than a side may be: refused by the decoder's own limits.
        huge[16..20].copy_from_slice(&(1u32 << 20).to_be_bytes());
        huge[20..24].copy_from_slice(&1u32.to_be_bytes());
        let crc = crc32(&huge[12..29]);
        huge[29..33].copy_from_slice(&crc.to_be_bytes());
        assert!(decode_image(&huge).is_err());
    }

    /// The CRC-32 of PNG chunks (ISO 3309, as the PNG specification's annex D computes it).
    fn crc32(bytes: &[u8]) -> u32 {
        let mut c = 0xffff_ffffu32;
        for &b in bytes {
            c ^= b as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 { 0xedb8_8320 ^ (c >> 1) } else { c >> 1 };
            }
        }
        !c
    }

    #[test]
    fn the_cache_decodes_once() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("t.png");
        std::fs::write(&file, png(1, 1, &[[1, 2, 3, 4]])).unwrap();
        let mut loader = TextureLoader::default();
        let a = loader.file(&file).unwrap();
        let b = loader.file(&dir.path().join(".").join("t.png")).unwrap();
        assert!(Arc::ptr_eq(&a, &b));
        let missing = loader.file(&dir.path().join("nope.png")).unwrap_err();
        assert!(missing.contains("cannot read"), "{missing}");
    }
}
