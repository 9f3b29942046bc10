//! Rendering an image in pieces: a [`PixelWindow`] is any rectangle of the image, a [`TileSpec`]
//! (`K/N`) is the `K`-th of `N` horizontal strips that englobe cuts (of equal height, or of equal
//! predicted cost: [`balance`]), and [`file`] and [`assemble`] write such a piece as an OpenEXR
//! tile and put the pieces back together.
//!
//! The design follows pbrt-v4's `--pixelbounds` and `imgtool assemble`: a piece holds exactly the
//! values a full render gives its pixels (every pixel's samples depend on the seed and the pixel
//! alone, see [`crate::sampler::PixelSampler`]), so assembling the pieces gives the full image bit for
//! bit. What pbrt leaves to the user, englobe checks: every tile names the scene it was rendered
//! from (a digest of the scene, its meshes and the options, see [`crate::digest`]) and englobe's
//! version, and assembly refuses tiles of different renders, overlaps and gaps.

pub mod assemble;
pub mod balance;
pub mod file;

use std::fmt;
use std::str::FromStr;

/// A rectangle of pixels: columns `x0..x1`, rows `y0..y1` (half-open, as pbrt's `--pixelbounds`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PixelWindow {
    /// First column.
    pub x0: u32,
    /// One past the last column.
    pub x1: u32,
    /// First row.
    pub y0: u32,
    /// One past the last row.
    pub y1: u32,
}

impl PixelWindow {
    /// The whole of a `width` x `height` image.
    pub fn full(width: u32, height: u32) -> Self {
        PixelWindow { x0: 0, x1: width, y0: 0, y1: height }
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }

    /// Number of pixels.
    pub fn area(&self) -> u64 {
        self.width() as u64 * self.height() as u64
    }

    /// Whether column `x`, row `y` is inside.
    pub fn contains(&self, x: u32, y: u32) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }

    /// The pixels both windows hold, if any.
    pub fn intersection(&self, other: &PixelWindow) -> Option<PixelWindow> {
        let w = PixelWindow {
            x0: self.x0.max(other.x0),
            x1: self.x1.min(other.x1),
            y0: self.y0.max(other.y0),
            y1: self.y1.min(other.y1),
        };
        (w.x0 < w.x1 && w.y0 < w.y1).then_some(w)
    }

    /// Checks that the window is not empty and lies inside a `width` x `height` image.
    pub fn check_inside(&self, width: u32, height: u32) -> Result<(), String> {
        if self.x0 >= self.x1 || self.y0 >= self.y1 {
            return Err(format!("pixel bounds {self}: the window is empty (expected x0 < x1 and y0 < y1)"));
        }
        if self.x1 > width || self.y1 > height {
            return Err(format!("pixel bounds {self}: outside the {width}x{height} image"));
        }
        Ok(())
    }
}

impl fmt::Display for PixelWindow {
    /// `x0,x1,y0,y1`, the form [`PixelWindow::from_str`] reads.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{},{},{}", self.x0, self.x1, self.y0, self.y1)
    }
}

impl FromStr for PixelWindow {
    type Err = String;

    /// Reads `X0,X1,Y0,Y1` (pbrt's order).
    fn from_str(s: &str) -> Result<Self, String> {
        let numbers: Vec<&str> = s.split(',').map(str::trim).collect();
        let expected = || format!("pixel bounds `{s}`: expected X0,X1,Y0,Y1 (four whole numbers, x0 < x1, y0 < y1)");
        let [x0, x1, y0, y1] = numbers.as_slice() else {
            return Err(expected());
        };
        let n = |t: &str| t.parse::<u32>().map_err(|_| expected());
        let window = PixelWindow { x0: n(x0)?, x1: n(x1)?, y0: n(y0)?, y1: n(y1)? };
        if window.x0 >= window.x1 || window.y0 >= window.y1 {
            return Err(expected());
        }
        Ok(window)
    }
}

/// Tile `index` of `count`: the image cut into `count` horizontal strips of (nearly) equal height.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TileSpec {
    /// Which strip, from 0 (the top) to `count - 1`: a Slurm array task's `SLURM_ARRAY_TASK_ID`.
    pub index: u32,
    /// How many strips.
    pub count: u32,
}

impl TileSpec {
    /// The rows of the strip in a `width` x `height` image: rows `index * height / count` to
    /// `(index + 1) * height / count`, so strips differ in height by one row at most. Refused when
    /// there are more strips than rows.
    pub fn window(&self, width: u32, height: u32) -> Result<PixelWindow, String> {
        if self.count > height {
            return Err(format!(
                "tile {self}: {} tiles for an image of {height} rows; at most one tile per row",
                self.count
            ));
        }
        let row = |i: u32| (i as u64 * height as u64 / self.count as u64) as u32;
        Ok(PixelWindow { x0: 0, x1: width, y0: row(self.index), y1: row(self.index + 1) })
    }

    /// The `count` tiles of a cut.
    pub fn all(count: u32) -> impl Iterator<Item = TileSpec> {
        (0..count).map(move |index| TileSpec { index, count })
    }
}

impl fmt::Display for TileSpec {
    /// `K/N`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl FromStr for TileSpec {
    type Err = String;

    /// Reads `K/N` with `0 <= K < N`.
    fn from_str(s: &str) -> Result<Self, String> {
        let expected = || format!("tile `{s}`: expected K/N, tile K (from 0) of N, with K < N");
        let (k, n) = s.split_once('/').ok_or_else(expected)?;
        let (index, count) =
            (k.trim().parse::<u32>().map_err(|_| expected())?, n.trim().parse::<u32>().map_err(|_| expected())?);
        if index >= count {
            return Err(expected());
        }
        Ok(TileSpec { index, count })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_cover_every_row_once_in_order() {
        for (height, count) in [(48, 1), (48, 4), (48, 7), (5, 5), (1000, 13)] {
            let mut next = 0;
            for tile in TileSpec::all(count) {
                let w = tile.window(64, height).unwrap();
                assert_eq!((w.x0, w.x1, w.y0), (0, 64, next), "{tile}");
                assert!(w.height() >= height / count && w.height() <= height / count + 1);
                next = w.y1;
            }
            assert_eq!(next, height);
        }
        assert!(TileSpec { index: 0, count: 6 }.window(8, 5).unwrap_err().contains("at most one tile per row"));
    }

    #[test]
    fn parses_and_prints_windows_and_tiles() {
        let w: PixelWindow = "0, 16,8,24".parse().unwrap();
        assert_eq!(w, PixelWindow { x0: 0, x1: 16, y0: 8, y1: 24 });
        assert_eq!(w.to_string().parse::<PixelWindow>(), Ok(w));
        for bad in ["", "1,2,3", "1,2,3,4,5", "4,2,0,1", "0,1,1,1", "a,1,0,1", "-1,1,0,1"] {
            assert!(bad.parse::<PixelWindow>().unwrap_err().contains("X0,X1,Y0,Y1"), "{bad}");
        }
        assert_eq!("3/8".parse::<TileSpec>(), Ok(TileSpec { index: 3, count: 8 }));
        for bad in ["8/8", "3", "3/", "/8", "-1/8", "1/0"] {
            assert!(bad.parse::<TileSpec>().is_err(), "{bad}");
        }
        assert!(w.check_inside(16, 24).is_ok());
        assert!(w.check_inside(16, 23).unwrap_err().contains("outside the 16x23 image"));
    }

    #[test]
    fn intersection_of_windows() {
        let a = PixelWindow { x0: 0, x1: 10, y0: 0, y1: 10 };
        let b = PixelWindow { x0: 5, x1: 20, y0: 9, y1: 12 };
        assert_eq!(a.intersection(&b), Some(PixelWindow { x0: 5, x1: 10, y0: 9, y1: 10 }));
        assert_eq!(a.intersection(&PixelWindow { x0: 10, x1: 11, y0: 0, y1: 1 }), None);
    }
}
