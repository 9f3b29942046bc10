//! A tile on disk: an OpenEXR file of 32-bit float RGB, ZIP-compressed (lossless), whose data
//! window is the tile and whose display window is the whole image. Its header also records what
//! assembly checks: the digest of the scene and options ([`crate::digest`]), englobe's version,
//! the `K/N` of the cut if the tile is one, and a digest of all that and of the pixel values, so
//! that a tile changed by one byte after it was rendered is caught rather than assembled.

use std::io::{BufReader, Cursor};
use std::path::{Path, PathBuf};

use englobe::Vec3;
use exr::meta::attribute::{AttributeValue, IntegerBounds, SampleType, Text};
use exr::prelude::{Image, Layer, LayerAttributes, ReadChannels, ReadLayers, SpecificChannels, Vec2, WritableImage};

use super::{PixelWindow, TileSpec};
use crate::film::Film;
use crate::output::{EXR_ENCODING, OutputError, write_atomically};
use englobe_scene::model::MAX_EXPOSURE;
use englobe_scene::{OutputSettings, ToneMap};

/// The version of englobe that tiles record and assembly compares.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

const VERSION_KEY: &str = "englobeVersion";
const SCENE_KEY: &str = "englobeScene";
const TILE_KEY: &str = "englobeTile";
const CONTENT_KEY: &str = "englobeContent";
const OUTPUT_KEY: &str = "englobeOutput";

/// What a tile says about itself.
#[derive(Clone, Debug, PartialEq)]
pub struct TileHeader {
    /// Size of the whole image.
    pub full_width: u32,
    /// Size of the whole image.
    pub full_height: u32,
    /// The pixels the tile holds.
    pub window: PixelWindow,
    /// Digest of the scene and options it was rendered with.
    pub scene_digest: String,
    /// englobe's version that rendered it.
    pub version: String,
    /// Its place in a cut, if it was rendered as `--tile K/N`.
    pub tile: Option<TileSpec>,
    /// How the assembled image is to be written (exposure, tone map, half floats): the render's
    /// choice, which changes no pixel of the tile, so assembly uses it unless told otherwise.
    pub output: OutputSettings,
}

/// The text of `output` in a tile's header: `exposure=EV tonemap=NAME half=BOOL`, the exposure
/// in the shortest form that reads back to the same `f32`.
pub fn output_text(output: &OutputSettings) -> String {
    format!("exposure={:?} tonemap={} half={}", output.exposure, output.tonemap.name(), output.exr_half)
}

/// Reads [`output_text`]'s form back; anything else is refused with what was expected.
pub fn parse_output_text(text: &str) -> Result<OutputSettings, String> {
    let expected = || format!("output settings `{text}`: expected `exposure=EV tonemap=none|filmic half=true|false`");
    let mut parts = text.split(' ');
    let mut field = |key: &str| parts.next().and_then(|p| p.strip_prefix(key)).and_then(|p| p.strip_prefix('='));
    let exposure = field("exposure").and_then(|e| e.parse::<f32>().ok()).filter(|e| e.abs() <= MAX_EXPOSURE);
    let tonemap = match field("tonemap") {
        Some("none") => Some(ToneMap::None),
        Some("filmic") => Some(ToneMap::Filmic),
        _ => None,
    };
    let half = field("half").and_then(|h| h.parse::<bool>().ok());
    match (exposure, tonemap, half, parts.next()) {
        (Some(exposure), Some(tonemap), Some(exr_half), None) => Ok(OutputSettings { exposure, tonemap, exr_half }),
        _ => Err(expected()),
    }
}

/// Why a tile could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum TileError {
    /// Writing failed.
    #[error(transparent)]
    Write(#[from] OutputError),
    /// The file could not be opened.
    #[error("{}: cannot read: {source}", path.display())]
    Io {
        /// The tile.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The file is not an OpenEXR file englobe can read.
    #[error("{}: not a readable OpenEXR file: {source}", path.display())]
    Exr {
        /// The tile.
        path: PathBuf,
        /// The decoder's complaint.
        #[source]
        source: exr::error::Error,
    },
    /// The file is an OpenEXR image but not an englobe tile, or its contents contradict its header.
    #[error("{}: {why}", path.display())]
    Invalid {
        /// The tile.
        path: PathBuf,
        /// What is wrong.
        why: String,
    },
}

/// Writes `film` (the tile's pixels, of the window's size) as a tile, atomically.
pub fn write_tile(path: &Path, header: &TileHeader, film: &Film) -> Result<(), TileError> {
    let w = header.window;
    assert_eq!((film.width(), film.height()), (w.width(), w.height()), "the film is the tile's window");
    let pixels = film.pixels();
    let width = film.width() as usize;
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let v = pixels[p.y() * width + p.x()];
        (v.x, v.y, v.z)
    });
    let mut attributes =
        LayerAttributes { layer_position: Vec2(w.x0 as i32, w.y0 as i32), ..LayerAttributes::default() };
    let mut text = |key: &str, value: String| {
        attributes.other.insert(Text::new_or_panic(key), AttributeValue::Text(Text::new_or_panic(value)));
    };
    text(VERSION_KEY, header.version.clone());
    text(SCENE_KEY, header.scene_digest.clone());
    text(CONTENT_KEY, content_digest(header, pixels));
    text(OUTPUT_KEY, output_text(&header.output));
    if let Some(tile) = header.tile {
        text(TILE_KEY, tile.to_string());
    }
    let layer = Layer::new((width, film.height() as usize), attributes, EXR_ENCODING, channels);
    let mut image = Image::from_layer(layer);
    image.attributes.display_window =
        IntegerBounds::new((0, 0), (header.full_width as usize, header.full_height as usize));
    let mut bytes = Cursor::new(Vec::new());
    image
        .write()
        .non_parallel()
        .to_buffered(&mut bytes)
        .map_err(|source| TileError::Exr { path: path.to_owned(), source })?;
    write_atomically(path, |out| {
        std::io::Write::write_all(out, bytes.get_ref())
            .map_err(|error| OutputError::Io { path: path.to_owned(), error })
    })?;
    Ok(())
}

/// Reads a tile: its header and its pixels (a film of the window's size). Checks that it is an
/// englobe tile, that its window lies inside the image and that its pixels are those it was
/// written with.
pub fn read_tile(path: &Path) -> Result<(TileHeader, Film), TileError> {
    let file = std::fs::File::open(path).map_err(|source| TileError::Io { path: path.to_owned(), source })?;
    read_tile_from(BufReader::new(file), path)
}

/// [`read_tile`] from bytes already in memory; `path` names them in errors.
pub fn read_tile_from(
    reader: impl std::io::Read + std::io::Seek,
    path: &Path,
) -> Result<(TileHeader, Film), TileError> {
    let exr_error = |source| TileError::Exr { path: path.to_owned(), source };
    let invalid = |why: String| TileError::Invalid { path: path.to_owned(), why };
    let mut reader = reader;
    // The header first, so that sizes and channels are checked before any pixel is allocated.
    let meta = exr::meta::MetaData::read_from_buffered(&mut reader, false).map_err(exr_error)?;
    let [header] = meta.headers.as_slice() else {
        return Err(invalid(format!("{} layers; an englobe tile has one", meta.headers.len())));
    };
    let names: Vec<String> = header.channels.list.iter().map(|c| c.name.to_string()).collect();
    if names != ["B", "G", "R"] || header.channels.list.iter().any(|c| c.sample_type != SampleType::F32) {
        return Err(invalid(format!("channels {names:?}; an englobe tile has 32-bit float R, G and B")));
    }
    let display = header.shared_attributes.display_window;
    let (full_width, full_height) = (display.size.x() as u64, display.size.y() as u64);
    if display.position.x() != 0 || display.position.y() != 0 {
        return Err(invalid("the display window does not start at 0,0".into()));
    }
    if full_width == 0 || full_height == 0 || full_width * full_height > englobe_scene::MAX_PIXELS {
        return Err(invalid(format!("image size {full_width}x{full_height} out of range")));
    }
    let position = header.own_attributes.layer_position;
    let size = header.layer_size;
    let (x0, y0) = (position.x() as i64, position.y() as i64);
    let (x1, y1) = (x0 + size.x() as i64, y0 + size.y() as i64);
    if x0 < 0 || y0 < 0 || x1 > full_width as i64 || y1 > full_height as i64 || x0 >= x1 || y0 >= y1 {
        return Err(invalid(format!(
            "data window {x0},{x1},{y0},{y1} is not inside the {full_width}x{full_height} image"
        )));
    }
    let text = |key: &str| -> Result<String, TileError> {
        match header.own_attributes.other.get(&Text::new_or_panic(key)) {
            Some(AttributeValue::Text(t)) => Ok(t.to_string()),
            _ => Err(invalid(format!("no `{key}` attribute: not a tile rendered by englobe"))),
        }
    };
    let tile = match header.own_attributes.other.get(&Text::new_or_panic(TILE_KEY)) {
        None => None,
        Some(AttributeValue::Text(t)) => Some(t.to_string().parse::<TileSpec>().map_err(invalid)?),
        Some(_) => return Err(invalid(format!("the `{TILE_KEY}` attribute is not text"))),
    };
    let tile_header = TileHeader {
        full_width: full_width as u32,
        full_height: full_height as u32,
        window: PixelWindow { x0: x0 as u32, x1: x1 as u32, y0: y0 as u32, y1: y1 as u32 },
        scene_digest: text(SCENE_KEY)?,
        version: text(VERSION_KEY)?,
        tile,
        output: parse_output_text(&text(OUTPUT_KEY)?).map_err(invalid)?,
    };
    let expected_content = text(CONTENT_KEY)?;

    reader.rewind().map_err(|source| TileError::Io { path: path.to_owned(), source })?;
    let (width, height) = (size.x(), size.y());
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgb_channels(
            move |_, _| vec![Vec3::ZERO; width * height],
            move |pixels: &mut Vec<Vec3>, p: Vec2<usize>, (r, g, b): (f32, f32, f32)| {
                if let Some(v) = pixels.get_mut(p.y() * width + p.x()) {
                    *v = Vec3::new(r, g, b);
                }
            },
        )
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_buffered(reader)
        .map_err(exr_error)?;
    let pixels = image.layer_data.channel_data.pixels;
    if content_digest(&tile_header, &pixels) != expected_content {
        return Err(invalid(
            "its header or pixels do not match the digest it was written with: the file was changed".into(),
        ));
    }
    let mut film = Film::new(width as u32, height as u32);
    for (i, v) in pixels.into_iter().enumerate() {
        film.set((i % width) as u32, (i / width) as u32, v);
    }
    Ok((tile_header, film))
}

/// BLAKE3 of what the header says and of the pixels' bits, row by row, as hexadecimal.
fn content_digest(header: &TileHeader, pixels: &[Vec3]) -> String {
    let mut h = blake3::Hasher::new();
    let tile = header.tile.map(|t| t.to_string()).unwrap_or_default();
    let what = format!(
        "{}x{} {} {} {} {tile} {}|",
        header.full_width,
        header.full_height,
        header.window,
        header.scene_digest,
        header.version,
        output_text(&header.output)
    );
    h.update(what.as_bytes());
    for p in pixels {
        for c in p.to_array() {
            h.update(&c.to_bits().to_le_bytes());
        }
    }
    h.finalize().to_hex().to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(window: PixelWindow) -> TileHeader {
        TileHeader {
            full_width: 10,
            full_height: 6,
            window,
            scene_digest: "ab".repeat(32),
            version: VERSION.into(),
            tile: Some(TileSpec { index: 1, count: 3 }),
            output: OutputSettings { exposure: -1.25, tonemap: ToneMap::Filmic, exr_half: true },
        }
    }

    fn film(w: u32, h: u32) -> Film {
        let mut f = Film::new(w, h);
        for y in 0..h {
            for x in 0..w {
                f.set(x, y, Vec3::new(x as f32 * 0.1, y as f32 + 0.5, -1.0e-30));
            }
        }
        f
    }

    #[test]
    fn a_tile_round_trips_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.exr");
        let h = header(PixelWindow { x0: 0, x1: 10, y0: 2, y1: 4 });
        let f = film(10, 2);
        write_tile(&path, &h, &f).unwrap();
        let (h2, f2) = read_tile(&path).unwrap();
        assert_eq!(h2, h);
        assert_eq!(
            f2.pixels().iter().map(|p| p.to_array().map(f32::to_bits)).collect::<Vec<_>>(),
            f.pixels().iter().map(|p| p.to_array().map(f32::to_bits)).collect::<Vec<_>>()
        );
    }

    #[test]
    fn output_settings_read_back_exactly_and_bad_ones_are_refused() {
        for output in [
            OutputSettings::default(),
            OutputSettings { exposure: 0.1, tonemap: ToneMap::Filmic, exr_half: true },
            OutputSettings { exposure: -63.999, tonemap: ToneMap::None, exr_half: false },
        ] {
            assert_eq!(parse_output_text(&output_text(&output)), Ok(output));
        }
        assert_eq!(output_text(&OutputSettings::default()), "exposure=0.0 tonemap=none half=false");
        for bad in [
            "",
            "exposure=1 tonemap=none",
            "exposure=1 tonemap=aces half=false",
            "exposure=99 tonemap=none half=false",
            "exposure=NaN tonemap=none half=false",
            "exposure=0 tonemap=none half=false extra",
            "tonemap=none exposure=0 half=false",
        ] {
            assert!(parse_output_text(bad).unwrap_err().contains("expected `exposure=EV"), "{bad}");
        }
    }

    #[test]
    fn one_byte_changed_anywhere_in_a_tile_is_caught() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.exr");
        write_tile(&path, &header(PixelWindow { x0: 2, x1: 7, y0: 1, y1: 5 }), &film(5, 4)).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let mut accepted = Vec::new();
        for i in 0..bytes.len() {
            let mut changed = bytes.clone();
            changed[i] ^= 0x10;
            if let Ok((h, f)) = read_tile_from(Cursor::new(&changed), &path) {
                accepted.push((i, h, f));
            }
        }
        // A flipped bit may land where nothing is read (padding or an attribute englobe ignores),
        // never in what assembly uses.
        let (h0, f0) = read_tile(&path).unwrap();
        for (i, h, f) in accepted {
            assert_eq!((h, f), (h0.clone(), f0.clone()), "byte {i} changed what the tile says");
        }
    }

    #[test]
    fn other_exr_files_are_refused_with_the_reason() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("plain.exr");
        crate::write_image(&Film::new(4, 4), &path).unwrap();
        let e = read_tile(&path).unwrap_err().to_string();
        assert!(e.contains("plain.exr") && e.contains("not a tile rendered by englobe"), "{e}");
        let e = read_tile_from(Cursor::new(b"not an exr file"), Path::new("x.exr")).unwrap_err().to_string();
        assert!(e.starts_with("x.exr: not a readable OpenEXR file"), "{e}");
    }
}
