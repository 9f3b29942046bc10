//! The environment: the light that arrives from infinitely far away, which rays that leave the
//! scene see. Three kinds: a constant colour, a simple sky (a gradient from the horizon to the
//! zenith over a constant ground), or an equirectangular (latitude-longitude) map read from an
//! OpenEXR or Radiance `.hdr` file, decoded with the `image` crate.
//!
//! The map's layout (the renderer's `environment` module maps directions to it): the top row is
//! straight up (+y), the bottom row straight down; the centre column looks along +x and the
//! columns run towards +z (a quarter of the way right of the centre is +z, the left and right edges
//! are -x). That is Blender's orientation of a world texture once its z-up axes are turned y-up
//! as glTF exporters turn them (Blender's -y, its front, becomes +z).
//!
//! The file's size and the map's pixel count are checked before anything is allocated; pixels
//! must be finite (negative values, which some encoders leave around zero, are read as 0).

use std::fmt;
use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use englobe::Vec3;

/// Largest environment file read, in bytes.
pub const MAX_ENVIRONMENT_FILE_BYTES: u64 = 1 << 30;
/// Most pixels of an environment map (2^25: an 8192 x 4096 map).
pub const MAX_ENVIRONMENT_PIXELS: u64 = 1 << 25;

/// The light from infinitely far away, as the scene's `[environment]` table describes it.
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    /// What it looks like.
    pub sky: Sky,
    /// Multiplies every radiance of `sky`.
    pub intensity: f32,
    /// Turn of the environment about +y, in degrees, counter-clockwise seen from above (+z
    /// towards +x): what the map shows along +x is seen along `(cos r, 0, -sin r)`.
    pub rotation_degrees: f32,
}

/// The radiance of each direction, before the environment's intensity.
#[derive(Clone, Debug, PartialEq)]
pub enum Sky {
    /// The same radiance from every direction.
    Constant(Vec3),
    /// A sky: `horizon + (zenith - horizon) * y` for directions with `y >= 0` (unit directions, so
    /// `y` is the sine of the elevation), `ground` below the horizon.
    Gradient {
        /// Radiance straight up.
        zenith: Vec3,
        /// Radiance at the horizon.
        horizon: Vec3,
        /// Radiance of every direction below the horizon.
        ground: Vec3,
    },
    /// An equirectangular map.
    Map(Arc<EnvironmentMap>),
}

/// An equirectangular map of linear RGB radiance, row by row from the top (straight up).
#[derive(Clone, PartialEq)]
pub struct EnvironmentMap {
    /// The file it was read from (for messages).
    pub path: PathBuf,
    /// Columns (longitude).
    pub width: u32,
    /// Rows (latitude).
    pub height: u32,
    /// `width * height` pixels, each finite and at least 0 in every channel.
    pub pixels: Vec<Vec3>,
}

impl fmt::Debug for EnvironmentMap {
    // Half a million pixels are no help in a message: the file and the size say which map it is.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "EnvironmentMap({}, {}x{})", self.path.display(), self.width, self.height)
    }
}

impl EnvironmentMap {
    /// The pixel at column `x`, row `y` (row 0 is the top).
    #[inline]
    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[(y * self.width + x) as usize]
    }
}

/// Why an environment map could not be read: the file and what is wrong.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}: {why}", path.display())]
pub struct EnvironmentError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong.
    pub why: String,
}

/// Reads an environment map from `path` (OpenEXR or Radiance HDR, told apart by their contents).
pub fn load_environment_map(path: &Path) -> Result<EnvironmentMap, EnvironmentError> {
    let fail = |why: String| EnvironmentError { path: path.to_owned(), why };
    let meta = std::fs::metadata(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    if meta.is_dir() {
        return Err(fail("is a folder, expected an environment map (.exr or .hdr)".into()));
    }
    if meta.len() > MAX_ENVIRONMENT_FILE_BYTES {
        return Err(fail(format!(
            "{} bytes is larger than the {MAX_ENVIRONMENT_FILE_BYTES}-byte limit for environment maps",
            meta.len()
        )));
    }
    let file = std::fs::File::open(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    let bytes = crate::mesh::read_at_most(file, meta.len() as usize, MAX_ENVIRONMENT_FILE_BYTES + 1)
        .map_err(|e| fail(format!("cannot read: {e}")))?;
    if bytes.len() as u64 > MAX_ENVIRONMENT_FILE_BYTES {
        return Err(fail(format!("the file is larger than the {MAX_ENVIRONMENT_FILE_BYTES}-byte limit")));
    }
    decode_environment_map(&bytes, path)
}

/// Decodes an environment map from the bytes of an OpenEXR or Radiance HDR file; `path` names
/// them in errors and in the map.
pub fn decode_environment_map(bytes: &[u8], path: &Path) -> Result<EnvironmentMap, EnvironmentError> {
    let fail = |why: String| EnvironmentError { path: path.to_owned(), why };
    let reader = || {
        let r = image::ImageReader::new(Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| fail(format!("cannot read: {e}")))?;
        match r.format() {
            Some(image::ImageFormat::OpenExr | image::ImageFormat::Hdr) => Ok(r),
            Some(other) => Err(fail(format!(
                "a {other:?} image; an environment map is an OpenEXR (.exr) or Radiance (.hdr) file of linear radiance"
            ))),
            None => Err(fail("not an OpenEXR (.exr) or Radiance (.hdr) file".into())),
        }
    };
    // The header alone first: the size is refused before any pixel is allocated.
    let (width, height) = reader()?.into_dimensions().map_err(|e| fail(format!("cannot decode: {e}")))?;
    let pixels = width as u64 * height as u64;
    if width == 0 || height == 0 || pixels > MAX_ENVIRONMENT_PIXELS {
        return Err(fail(format!(
            "a {width}x{height} map: expected at least one pixel and at most {MAX_ENVIRONMENT_PIXELS} pixels"
        )));
    }
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(width);
    limits.max_image_height = Some(height);
    // The decoded image in four float channels, and a margin for the decoder's own buffers.
    limits.max_alloc = Some(pixels * 16 * 2 + (64 << 20));
    let mut r = reader()?;
    r.limits(limits);
    let decoded = r.decode().map_err(|e| fail(format!("cannot decode: {e}")))?.into_rgb32f();
    if decoded.dimensions() != (width, height) {
        return Err(fail(format!(
            "the header says {width}x{height} but {}x{} pixels were decoded",
            decoded.width(),
            decoded.height()
        )));
    }
    let mut out = Vec::with_capacity(pixels as usize);
    for (i, p) in decoded.pixels().enumerate() {
        let [r, g, b] = p.0;
        if !(r.is_finite() && g.is_finite() && b.is_finite()) {
            let (x, y) = (i as u64 % width as u64, i as u64 / width as u64);
            return Err(fail(format!("pixel ({x}, {y}) is ({r}, {g}, {b}): an environment map needs finite radiance")));
        }
        out.push(Vec3::new(r, g, b).max(Vec3::ZERO));
    }
    Ok(EnvironmentMap { path: path.to_owned(), width, height, pixels: out })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An OpenEXR file of `width` x `height` float pixels `pixel(x, y)`.
    fn exr_bytes(width: usize, height: usize, pixel: impl Fn(usize, usize) -> (f32, f32, f32) + Sync) -> Vec<u8> {
        use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
        let channels = SpecificChannels::rgb(|p: Vec2<usize>| pixel(p.x(), p.y()));
        let mut bytes = Cursor::new(Vec::new());
        Image::from_channels((width, height), channels).write().to_buffered(&mut bytes).unwrap();
        bytes.into_inner()
    }

    #[test]
    fn an_exr_map_decodes_row_by_row_from_the_top() {
        let bytes = exr_bytes(4, 2, |x, y| (x as f32, y as f32 * 10.0, -0.5));
        let map = decode_environment_map(&bytes, Path::new("small.exr")).unwrap();
        assert_eq!((map.width, map.height), (4, 2));
        assert_eq!(map.get(3, 0), Vec3::new(3.0, 0.0, 0.0), "negative values read as 0");
        assert_eq!(map.get(1, 1), Vec3::new(1.0, 10.0, 0.0));
        assert_eq!(format!("{map:?}"), "EnvironmentMap(small.exr, 4x2)");
    }

    #[test]
    fn a_radiance_hdr_map_decodes() {
        // The Radiance format: a header, a blank line, the resolution, then RGBE pixels (flat,
        // not run-length encoded). RGBE (128, 64, 32, 129) is (1, 0.5, 0.25).
        let mut bytes = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n".to_vec();
        bytes.extend([128, 64, 32, 129, 0, 0, 0, 0]);
        let map = decode_environment_map(&bytes, Path::new("tiny.hdr")).unwrap();
        assert_eq!((map.width, map.height), (2, 1));
        assert_eq!(map.get(0, 0), Vec3::new(1.0, 0.5, 0.25));
        assert_eq!(map.get(1, 0), Vec3::ZERO);
    }

    #[test]
    fn bad_maps_are_refused_naming_the_file() {
        let e = decode_environment_map(b"not an image at all", Path::new("junk.exr")).unwrap_err();
        assert!(e.to_string().starts_with("junk.exr: ") && e.to_string().contains("OpenEXR"), "{e}");
        let bytes = exr_bytes(2, 2, |x, _| (if x == 1 { f32::INFINITY } else { 1.0 }, 0.0, 0.0));
        let e = decode_environment_map(&bytes, Path::new("inf.exr")).unwrap_err();
        assert!(e.to_string().contains("pixel (1, 0)") && e.to_string().contains("finite"), "{e}");
        // A PNG is an image, but not of radiance.
        let mut png = Vec::new();
        image::RgbImage::new(2, 1).write_to(&mut Cursor::new(&mut png), image::ImageFormat::Png).unwrap();
        let e = decode_environment_map(&png, Path::new("ldr.png")).unwrap_err();
        assert!(e.to_string().contains("Png image"), "{e}");
        // A header that claims a huge image is refused before its pixels are allocated.
        let mut bytes = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n".to_vec();
        bytes.extend([0; 16]);
        let e = decode_environment_map(&bytes, Path::new("huge.hdr")).unwrap_err();
        assert!(e.to_string().contains("100000x100000") && e.to_string().contains("at most"), "{e}");
        let e = load_environment_map(Path::new("no/such/env.exr")).unwrap_err();
        assert!(e.to_string().starts_with("no/such/env.exr: cannot read"), "{e}");
    }
}
