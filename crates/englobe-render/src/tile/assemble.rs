//! Putting tiles back together. Assembly refuses, naming the tiles or pixels at fault, tiles of
//! different renders (scene digest, englobe version, image size or cut), a tile of a cut given
//! twice, windows that overlap and pixels that no tile covers; otherwise every pixel of the image
//! comes from exactly one tile, so the image is the one a single render gives, bit for bit.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;

use englobe_scene::OutputSettings;

use super::file::TileHeader;
use super::{PixelWindow, TileSpec};
use crate::film::Film;

/// A tile read from a file.
#[derive(Clone, Debug)]
pub struct Tile {
    /// Where it was read from, to name it in messages.
    pub path: PathBuf,
    /// What it says about itself.
    pub header: TileHeader,
    /// Its pixels, of its window's size.
    pub film: Film,
}

/// Why tiles do not make one image: every problem found, one per line.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("cannot assemble the tiles:\n{}", .problems.join("\n"))]
pub struct AssembleError {
    /// What is wrong, in words.
    pub problems: Vec<String>,
    /// Tiles of the cut that no file holds (empty if the tiles are not of a cut `K/N`).
    pub missing: Vec<TileSpec>,
}

/// At most this many overlaps or gaps are described; the rest are counted.
const MAX_REPORTED: usize = 8;

/// The tiles of a cut `K/N` that none of `tiles` is, in order; `count` is `N` (or `None` to take
/// it from the tiles). Empty when tiles of different cuts are mixed: [`assemble`] says so.
pub fn missing_tiles(tiles: &[Tile], count: Option<u32>) -> Vec<TileSpec> {
    let counts: Vec<u32> = tiles.iter().filter_map(|t| t.header.tile.map(|s| s.count)).collect();
    let Some(count) = count.or_else(|| counts.first().copied()) else {
        return Vec::new();
    };
    if counts.iter().any(|&c| c != count) {
        return Vec::new();
    }
    let present: std::collections::HashSet<u32> = tiles.iter().filter_map(|t| t.header.tile.map(|s| s.index)).collect();
    TileSpec::all(count).filter(|t| !present.contains(&t.index)).collect()
}

/// How the tiles ask the assembled image to be written: the output settings they all record, or
/// why there is no one answer (tiles of one render written with different settings, such as a
/// run repeated with another exposure: the caller must choose).
pub fn output_settings(tiles: &[Tile]) -> Result<OutputSettings, String> {
    let Some(first) = tiles.first() else { return Ok(OutputSettings::default()) };
    match tiles.iter().find(|t| t.header.output != first.header.output) {
        None => Ok(first.header.output),
        Some(other) => Err(format!(
            "the tiles ask for different output settings: {} has `{}`, {} has `{}`",
            first.path.display(),
            super::file::output_text(&first.header.output),
            other.path.display(),
            super::file::output_text(&other.header.output)
        )),
    }
}

/// The whole image from its tiles, or every reason it cannot be made.
pub fn assemble(tiles: &[Tile]) -> Result<Film, AssembleError> {
    let mut problems = Vec::new();
    let name = |t: &Tile| t.path.display().to_string();
    let Some(first) = tiles.first() else {
        return Err(AssembleError { problems: vec!["no tiles given".into()], missing: Vec::new() });
    };

    // One render: same scene and options, version, image size and cut.
    let render_of = |t: &Tile| {
        let h = &t.header;
        format!(
            "scene {}, englobe {}, {}x{} image",
            &h.scene_digest[..h.scene_digest.len().min(12)],
            h.version,
            h.full_width,
            h.full_height
        )
    };
    let mut renders: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for t in tiles {
        let h = &t.header;
        let key = format!("{}|{}|{}|{}", h.scene_digest, h.version, h.full_width, h.full_height);
        renders.entry(key).or_default().push(format!("{} ({})", name(t), render_of(t)));
    }
    if renders.len() > 1 {
        let mut message = format!("the tiles come from {} different renders:", renders.len());
        for group in renders.values() {
            let _ = write!(
                message,
                "\n  {}{}",
                group[0],
                if group.len() > 1 { format!(" and {} more like it", group.len() - 1) } else { String::new() }
            );
        }
        problems.push(message);
        return Err(AssembleError { problems, missing: Vec::new() });
    }

    // One cut (tiles given by their window alone may join it).
    let mut cuts: BTreeMap<u32, String> = BTreeMap::new();
    for t in tiles {
        if let Some(spec) = t.header.tile {
            cuts.entry(spec.count).or_insert_with(|| format!("{} is tile {spec}", name(t)));
        }
    }
    if cuts.len() > 1 {
        let examples: Vec<String> = cuts.into_values().collect();
        problems.push(format!("the tiles come from different cuts: {}", examples.join(", ")));
        return Err(AssembleError { problems, missing: Vec::new() });
    }

    // Each tile of a cut once.
    let mut by_index: BTreeMap<u32, Vec<&Tile>> = BTreeMap::new();
    for t in tiles {
        if let Some(spec) = t.header.tile {
            by_index.entry(spec.index).or_default().push(t);
        }
    }
    let mut duplicated = std::collections::HashSet::new();
    for (index, copies) in &by_index {
        if copies.len() > 1 {
            let count = copies[0].header.tile.map_or(0, |s| s.count);
            let names: Vec<String> = copies.iter().map(|t| name(t)).collect();
            problems.push(format!("tile {index}/{count} is given {} times: {}", copies.len(), names.join(", ")));
            duplicated.insert(*index);
        }
    }

    // No overlaps (tiles already reported as duplicates are not reported again).
    let mut overlaps = 0;
    for (i, a) in tiles.iter().enumerate() {
        for b in &tiles[i + 1..] {
            let same_tile =
                matches!((a.header.tile, b.header.tile), (Some(x), Some(y)) if x == y && duplicated.contains(&x.index));
            if let Some(common) = a.header.window.intersection(&b.header.window)
                && !same_tile
            {
                overlaps += 1;
                if overlaps <= MAX_REPORTED {
                    problems.push(format!("{} and {} overlap on pixels {common} (x0,x1,y0,y1)", name(a), name(b)));
                }
            }
        }
    }
    if overlaps > MAX_REPORTED {
        problems.push(format!("... and {} more overlaps", overlaps - MAX_REPORTED));
    }

    // No gaps.
    let (width, height) = (first.header.full_width, first.header.full_height);
    let mut covered = vec![false; width as usize * height as usize];
    for t in tiles {
        let w = t.header.window;
        for y in w.y0..w.y1 {
            covered[(y * width + w.x0) as usize..(y * width + w.x1) as usize].fill(true);
        }
    }
    let missing = missing_tiles(tiles, None);
    let gaps = uncovered_rows(&covered, width);
    if !gaps.is_empty() {
        let pixels: u64 = gaps.iter().map(PixelWindow::area).sum();
        let mut message = format!("{pixels} pixels are in no tile:");
        for g in gaps.iter().take(MAX_REPORTED) {
            let _ = write!(message, " {g}");
        }
        if gaps.len() > MAX_REPORTED {
            let _ = write!(message, " and {} more windows", gaps.len() - MAX_REPORTED);
        }
        message.push_str(" (x0,x1,y0,y1)");
        if !missing.is_empty() {
            let list: Vec<String> = missing.iter().map(ToString::to_string).collect();
            let _ = write!(message, "; missing tiles: {}", list.join(", "));
        }
        problems.push(message);
    }
    if !problems.is_empty() {
        return Err(AssembleError { problems, missing });
    }

    let mut film = Film::new(width, height);
    for t in tiles {
        let w = t.header.window;
        for y in 0..w.height() {
            for x in 0..w.width() {
                film.set(w.x0 + x, w.y0 + y, t.film.get(x, y));
            }
        }
    }
    Ok(film)
}

/// The uncovered pixels as windows: runs of uncovered pixels in each row, with runs of equal
/// columns in consecutive rows merged, so a missing strip reads as one window.
fn uncovered_rows(covered: &[bool], width: u32) -> Vec<PixelWindow> {
    let mut windows: Vec<PixelWindow> = Vec::new();
    for (y, row) in covered.chunks(width as usize).enumerate() {
        let y = y as u32;
        let mut x = 0;
        while x < width {
            if row[x as usize] {
                x += 1;
                continue;
            }
            let x0 = x;
            while x < width && !row[x as usize] {
                x += 1;
            }
            match windows.iter_mut().rev().find(|w| w.y1 == y && w.x0 == x0 && w.x1 == x) {
                Some(w) => w.y1 = y + 1,
                None => windows.push(PixelWindow { x0, x1: x, y0: y, y1: y + 1 }),
            }
        }
    }
    windows
}

#[cfg(test)]
mod tests {
    use super::*;
    use englobe::Vec3;

    fn tile(name: &str, spec: TileSpec, scene: &str) -> Tile {
        let window = spec.window(8, 6).unwrap();
        let mut film = Film::new(window.width(), window.height());
        for y in 0..window.height() {
            for x in 0..window.width() {
                film.set(x, y, Vec3::splat((window.x0 + x + 10 * (window.y0 + y)) as f32));
            }
        }
        Tile {
            path: name.into(),
            header: TileHeader {
                full_width: 8,
                full_height: 6,
                window,
                scene_digest: scene.repeat(64 / scene.len()),
                version: "1".into(),
                tile: Some(spec),
                output: Default::default(),
            },
            film,
        }
    }

    #[test]
    fn tiles_agree_on_the_output_settings_or_say_they_do_not() {
        let mut tiles = cut(3);
        assert_eq!(output_settings(&tiles), Ok(OutputSettings::default()));
        for t in &mut tiles {
            t.header.output.exposure = 1.5;
        }
        assert_eq!(output_settings(&tiles).unwrap().exposure, 1.5);
        tiles[2].header.output.tonemap = englobe_scene::ToneMap::Filmic;
        let e = output_settings(&tiles).unwrap_err();
        assert!(e.contains("t0.exr") && e.contains("t2.exr") && e.contains("tonemap=filmic"), "{e}");
        assert!(assemble(&tiles).is_ok(), "the pixels still assemble");
    }

    fn cut(count: u32) -> Vec<Tile> {
        TileSpec::all(count).map(|s| tile(&format!("t{}.exr", s.index), s, "a")).collect()
    }

    #[test]
    fn every_pixel_comes_from_its_tile() {
        for count in [1, 4, 6] {
            let film = assemble(&cut(count)).unwrap();
            for y in 0..6 {
                for x in 0..8 {
                    assert_eq!(film.get(x, y), Vec3::splat((x + 10 * y) as f32));
                }
            }
        }
    }

    #[test]
    fn a_missing_tile_is_named_with_its_pixels() {
        let mut tiles = cut(3);
        tiles.remove(1);
        let e = assemble(&tiles).unwrap_err();
        assert_eq!(e.missing, vec![TileSpec { index: 1, count: 3 }]);
        assert_eq!(e.problems, vec!["16 pixels are in no tile: 0,8,2,4 (x0,x1,y0,y1); missing tiles: 1/3"]);
        assert_eq!(missing_tiles(&tiles, None), e.missing);
        assert_eq!(missing_tiles(&tiles, Some(3)), e.missing);
        assert!(missing_tiles(&cut(3), None).is_empty());
    }

    #[test]
    fn a_duplicate_tile_and_an_overlap_are_named() {
        let mut tiles = cut(3);
        let mut copy = tiles[2].clone();
        copy.path = "copy.exr".into();
        tiles.push(copy);
        let e = assemble(&tiles).unwrap_err();
        assert_eq!(e.problems, vec!["tile 2/3 is given 2 times: t2.exr, copy.exr"]);

        let mut tiles = cut(2);
        tiles[1].header.tile = None;
        tiles[1].header.window.y0 = 2;
        tiles[1].film = Film::new(8, 4);
        let e = assemble(&tiles).unwrap_err();
        assert_eq!(e.problems, vec!["t0.exr and t1.exr overlap on pixels 0,8,2,3 (x0,x1,y0,y1)"]);
    }

    #[test]
    fn tiles_of_another_render_are_refused() {
        let mut tiles = cut(2);
        tiles[1] = tile("other.exr", TileSpec { index: 1, count: 2 }, "b");
        let e = assemble(&tiles).unwrap_err();
        assert!(e.problems[0].starts_with("the tiles come from 2 different renders:"), "{e}");
        assert!(e.to_string().contains("other.exr (scene bbbbbbbbbbbb"), "{e}");
        let mut tiles = cut(2);
        tiles[0].header.version = "2".into();
        assert!(assemble(&tiles).unwrap_err().to_string().contains("englobe 2,"));
        let mut tiles = cut(2);
        tiles.push(tile("three.exr", TileSpec { index: 2, count: 3 }, "a"));
        assert_eq!(
            assemble(&tiles).unwrap_err().problems,
            vec!["the tiles come from different cuts: t0.exr is tile 0/2, three.exr is tile 2/3"]
        );
    }

    #[test]
    fn gaps_are_merged_into_windows() {
        let mut covered = vec![true; 4 * 3];
        covered[1] = false;
        covered[5] = false;
        covered[11] = false;
        assert_eq!(
            uncovered_rows(&covered, 4),
            vec![PixelWindow { x0: 1, x1: 2, y0: 0, y1: 2 }, PixelWindow { x0: 3, x1: 4, y0: 2, y1: 3 }]
        );
    }
}
