//! Writing images: PNG (8-bit sRGB) or OpenEXR (linear float), always atomically: the image is
//! written to a temporary file in the destination's folder and renamed over the destination, so
//! an interrupted run never leaves a half-written file where a good image was. The same film
//! always gives the same bytes: EXR blocks are compressed in parallel but written in increasing
//! order (an EXR's "unspecified" line order, the `exr` crate's default, writes them in whatever
//! order the threads finish).

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use englobe_scene::OutputSettings;
use exr::prelude::{Blocks, Compression, Encoding, Image, LineOrder, SpecificChannels, Vec2, WritableImage, f16};
use image::{ImageFormat, RgbImage};

use crate::film::Film;

/// Why an image could not be written.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The extension is neither `.png` nor `.exr`.
    #[error("{}: unsupported image format; expected a file name ending in .png or .exr", .0.display())]
    UnknownFormat(PathBuf),
    /// The file system refused.
    #[error("{}: cannot write: {error}", path.display())]
    Io {
        /// The destination.
        path: PathBuf,
        /// What the system said (already part of the message, so not a separate source, which
        /// would print it twice).
        error: std::io::Error,
    },
    /// The encoder failed.
    #[error("{}: cannot encode: {error}", path.display())]
    Encode {
        /// The destination.
        path: PathBuf,
        /// The cause (part of the message).
        error: image::ImageError,
    },
    /// The OpenEXR encoder failed.
    #[error("{}: cannot encode: {error}", path.display())]
    EncodeExr {
        /// The destination.
        path: PathBuf,
        /// The cause (part of the message).
        error: exr::error::Error,
    },
}

/// The image formats englobe writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputFormat {
    /// 8-bit sRGB PNG.
    Png,
    /// 32-bit float linear OpenEXR.
    Exr,
}

impl OutputFormat {
    /// The format for a file name, from its extension.
    pub fn from_path(path: &Path) -> Result<Self, OutputError> {
        match path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).as_deref() {
            Some("png") => Ok(OutputFormat::Png),
            Some("exr") => Ok(OutputFormat::Exr),
            _ => Err(OutputError::UnknownFormat(path.to_owned())),
        }
    }
}

/// How englobe writes OpenEXR: ZIP compression of 16 scan lines at a time (lossless for floats),
/// blocks in increasing order, so that the bytes depend on the pixels alone.
pub const EXR_ENCODING: Encoding =
    Encoding { compression: Compression::ZIP16, blocks: Blocks::ScanLines, line_order: LineOrder::Increasing };

/// Writes the film to `path` (format from the extension), atomically, with the default output
/// settings: PNG values clipped, EXR in 32-bit floats.
pub fn write_image(film: &Film, path: &Path) -> Result<(), OutputError> {
    write_image_with(film, path, &OutputSettings::default())
}

/// Writes the film to `path` (format from the extension), atomically: a PNG with the exposure and
/// tone map of `settings` (see [`crate::tonemap`]), an EXR with the linear values themselves, in
/// half floats if `settings` ask.
pub fn write_image_with(film: &Film, path: &Path, settings: &OutputSettings) -> Result<(), OutputError> {
    let format = OutputFormat::from_path(path)?;
    write_atomically(path, |w| {
        let (wd, ht) = (film.width(), film.height());
        let result = match format {
            OutputFormat::Png => RgbImage::from_raw(wd, ht, film.to_display_srgb8(settings))
                .expect("the film holds exactly width * height pixels")
                .write_to(w, ImageFormat::Png),
            OutputFormat::Exr if settings.exr_half => {
                let pixels = film.pixels();
                return write_exr_rgb_half(w, path, wd, ht, |i| pixels[i].to_array());
            }
            OutputFormat::Exr => {
                let pixels = film.pixels();
                return write_exr_rgb(w, path, wd, ht, |i| pixels[i].to_array());
            }
        };
        result.map_err(|error| OutputError::Encode { path: path.to_owned(), error })
    })
}

/// Encodes a `width` x `height` RGB float image as OpenEXR with [`EXR_ENCODING`]; `pixel(i)` is
/// the `i`-th pixel, row by row. `path` names the destination in errors.
pub fn write_exr_rgb(
    w: impl std::io::Write + std::io::Seek,
    path: &Path,
    width: u32,
    height: u32,
    pixel: impl Sync + Fn(usize) -> [f32; 3],
) -> Result<(), OutputError> {
    let width = width as usize;
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let [r, g, b] = pixel(p.y() * width + p.x());
        (r, g, b)
    });
    Image::from_encoded_channels((width, height as usize), EXR_ENCODING, channels)
        .write()
        .to_buffered(w)
        .map_err(|error| OutputError::EncodeExr { path: path.to_owned(), error })
}

/// Encodes a `width` x `height` RGB image as OpenEXR in 16-bit half floats with [`EXR_ENCODING`]
/// (lossless for the halves themselves); `pixel(i)` is the `i`-th pixel, row by row. Values beyond
/// the largest half (65504) are written as it rather than as infinity.
pub fn write_exr_rgb_half(
    w: impl std::io::Write + std::io::Seek,
    path: &Path,
    width: u32,
    height: u32,
    pixel: impl Sync + Fn(usize) -> [f32; 3],
) -> Result<(), OutputError> {
    let width = width as usize;
    let half =
        |v: f32| if v.is_nan() { f16::NAN } else { f16::from_f32(v.clamp(-f16::MAX.to_f32(), f16::MAX.to_f32())) };
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let [r, g, b] = pixel(p.y() * width + p.x());
        (half(r), half(g), half(b))
    });
    Image::from_encoded_channels((width, height as usize), EXR_ENCODING, channels)
        .write()
        .to_buffered(w)
        .map_err(|error| OutputError::EncodeExr { path: path.to_owned(), error })
}

/// Runs `write` on a temporary file beside `path`, then renames it to `path`. On any error the
/// temporary file is removed and `path` is left as it was.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<&mut std::fs::File>) -> Result<(), OutputError>,
) -> Result<(), OutputError> {
    let io = |error| OutputError::Io { path: path.to_owned(), error: without_path(error) };
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".englobe-").suffix(".tmp");
    // Temporary files are private (0600) by default; the image must get the permissions any new
    // file would (0666 minus the umask, which the kernel applies).
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let mut tmp = builder.tempfile_in(dir).map_err(io)?;
    {
        let mut w = BufWriter::new(tmp.as_file_mut());
        write(&mut w)?;
        w.flush().map_err(io)?;
    }
    tmp.as_file().sync_all().map_err(io)?;
    tmp.persist(path).map_err(|e| io(e.error))?;
    Ok(())
}

/// The system's error without the path of the temporary file that `tempfile` adds to it: the
/// message names the destination, which is what the user asked for.
fn without_path(error: std::io::Error) -> std::io::Error {
    // tempfile wraps the system's error as "{error} at path {path:?}", keeping nothing else.
    if error.get_ref().is_none() {
        return error;
    }
    let text = error.to_string();
    match text.rfind(" at path \"") {
        Some(at) => std::io::Error::new(error.kind(), &text[..at]),
        None => error,
    }
}

/// Checks, before any work, that an image can be written at `path`: a known extension, a folder
/// that exists, and the right to create a file in it (tried with a file created and removed at
/// once), so that a long render never ends in "cannot write".
pub fn check_writable(path: &Path) -> Result<OutputFormat, OutputError> {
    // A folder is refused as one, before its name is judged as an image's.
    if path.is_dir() {
        check_file_writable(path)?;
    }
    let format = OutputFormat::from_path(path)?;
    check_file_writable(path)?;
    Ok(format)
}

/// Checks, before any work, that a file (of any kind: an image, statistics) can be written at
/// `path`: not a folder, in a folder that exists and takes a new file.
pub fn check_file_writable(path: &Path) -> Result<(), OutputError> {
    let refuse = |message: &str| OutputError::Io { path: path.to_owned(), error: std::io::Error::other(message) };
    if path.is_dir() {
        return Err(refuse("it is a folder"));
    }
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    match std::fs::metadata(dir) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => return Err(refuse(&format!("{} is not a folder", dir.display()))),
        Err(_) => return Err(refuse(&format!("the folder {} does not exist", dir.display()))),
    }
    tempfile::Builder::new()
        .prefix(".englobe-")
        .suffix(".tmp")
        .tempfile_in(dir)
        .map_err(|error| OutputError::Io { path: path.to_owned(), error: without_path(error) })?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_write_error_names_the_destination_and_its_cause_once() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("gone").join("out.png");
        let e = write_atomically(&path, |_| Ok(())).unwrap_err();
        // As the command line shows it: the message, then each source.
        let mut shown = e.to_string();
        let mut source = std::error::Error::source(&e);
        while let Some(s) = source {
            shown += &format!(": {s}");
            source = s.source();
        }
        assert!(shown.starts_with(&format!("{}: cannot write: ", path.display())), "{shown}");
        assert_eq!(shown.matches("os error").count(), 1, "{shown}");
        assert!(!shown.contains(".englobe-"), "the temporary file is not named: {shown}");
    }

    #[test]
    fn png_round_trips_and_replaces_atomically() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.png");
        let mut film = Film::new(3, 2);
        film.set(1, 0, englobe::Vec3::new(1.0, 0.0, 0.0));
        write_image(&film, &path).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (3, 2));
        assert_eq!(img.get_pixel(1, 0).0, [255, 0, 0]);
        // A failed write leaves the good image and no temporary file behind.
        let err = write_atomically(&path, |_| Err(OutputError::UnknownFormat(path.clone())));
        assert!(err.is_err());
        assert_eq!(image::open(&path).unwrap().to_rgb8(), img);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[cfg(unix)]
    #[test]
    fn images_are_readable_by_others_like_any_new_file() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.png");
        write_image(&Film::new(1, 1), &path).unwrap();
        let mode = std::fs::metadata(&path).unwrap().permissions().mode();
        assert_ne!(mode & 0o044, 0, "mode {mode:o}: group or others can read");
    }

    #[test]
    fn exr_round_trips_linear_values() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.exr");
        let mut film = Film::new(2, 2);
        film.set(0, 1, englobe::Vec3::new(4.5, 0.25, 0.0));
        write_image(&film, &path).unwrap();
        let img = image::open(&path).unwrap().to_rgb32f();
        assert_eq!(img.get_pixel(0, 1).0, [4.5, 0.25, 0.0]);
    }

    #[test]
    fn exr_bytes_depend_on_the_pixels_alone() {
        let dir = tempfile::tempdir().unwrap();
        let mut film = Film::new(300, 200);
        for y in 0..200 {
            for x in 0..300 {
                film.set(x, y, englobe::Vec3::new((x * y) as f32 * 1e-3, (x ^ y) as f32, 1.0 / (1 + x + y) as f32));
            }
        }
        let bytes: Vec<Vec<u8>> = (0..4)
            .map(|i| {
                let path = dir.path().join(format!("{i}.exr"));
                write_image(&film, &path).unwrap();
                std::fs::read(path).unwrap()
            })
            .collect();
        assert!(bytes.iter().all(|b| *b == bytes[0]));
        // Blocks compressed on several threads land in increasing order, not as they finish.
        let meta = exr::meta::MetaData::read_from_file(dir.path().join("0.exr"), false).unwrap();
        assert_eq!(meta.headers[0].line_order, LineOrder::Increasing);
    }

    #[test]
    fn half_exr_round_trips_within_half_precision() {
        use exr::meta::attribute::SampleType;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("half.exr");
        let mut film = Film::new(5, 3);
        let values = [0.0f32, 1.0, 0.1, 2.71, 1234.567, 6.1e-5, 1e-3, 65504.0, 1e9];
        for (i, v) in values.iter().enumerate() {
            film.set(i as u32 % 5, i as u32 / 5, englobe::Vec3::new(*v, v * 0.5, 2.0 * v));
        }
        let half = OutputSettings { exr_half: true, ..OutputSettings::default() };
        write_image_with(&film, &path, &half).unwrap();
        let meta = exr::meta::MetaData::read_from_file(&path, false).unwrap();
        assert!(meta.headers[0].channels.list.iter().all(|c| c.sample_type == SampleType::F16));
        assert_eq!(meta.headers[0].compression, Compression::ZIP16);
        let img = image::open(&path).unwrap().to_rgb32f();
        for (i, v) in values.iter().enumerate() {
            let got = img.get_pixel(i as u32 % 5, i as u32 / 5).0;
            for (g, want) in got.into_iter().zip([*v, v * 0.5, 2.0 * v]) {
                // Half floats keep 11 significant bits: a relative error of at most 2^-11 (and
                // the largest half, 65504, for anything beyond it).
                let want = want.min(65504.0);
                assert!((g - want).abs() <= want * 2f32.powi(-11) + 1e-7, "{want} read back as {g}");
            }
        }
        let full = dir.path().join("full.exr");
        write_image_with(&film, &full, &OutputSettings::default()).unwrap();
        assert!(std::fs::metadata(&path).unwrap().len() < std::fs::metadata(&full).unwrap().len());
    }

    #[test]
    fn exposure_and_tone_map_change_png_values_and_never_exr_ones() {
        let dir = tempfile::tempdir().unwrap();
        let mut film = Film::new(2, 1);
        film.set(0, 0, englobe::Vec3::new(0.1, 0.2, 4.0));
        let bright = OutputSettings { exposure: 1.0, tonemap: englobe_scene::ToneMap::Filmic, exr_half: false };
        let (png, exr) = (dir.path().join("a.png"), dir.path().join("a.exr"));
        write_image_with(&film, &png, &bright).unwrap();
        write_image_with(&film, &exr, &bright).unwrap();
        let got = image::open(&png).unwrap().to_rgb8().get_pixel(0, 0).0;
        let expected = [0.2f32, 0.4, 8.0].map(|v| crate::film::encode_srgb8(crate::tonemap::filmic(v)));
        assert_eq!(got, expected);
        assert_eq!(image::open(&exr).unwrap().to_rgb32f().get_pixel(0, 0).0, [0.1, 0.2, 4.0]);
    }

    #[test]
    fn unknown_extension_is_refused() {
        let e = write_image(&Film::new(1, 1), Path::new("x.jpg")).unwrap_err();
        assert!(e.to_string().contains(".png or .exr"), "{e}");
    }
}
