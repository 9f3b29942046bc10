//! The cost AOV: how much work the acceleration structure did for each pixel (nodes visited plus
//! exact primitive tests, summed over every ray the pixel cast: primary, shadow, reflected,
//! refracted). Written as a false-colour PNG with its colour bar (see [`crate::heatmap`]) or, for
//! analysis, as an OpenEXR file holding the raw counts.

use std::path::Path;

use image::ImageFormat;

use crate::heatmap::{Heatmap, HeatmapScale};
use crate::output::{OutputError, OutputFormat, write_atomically, write_exr_rgb};

/// Work per pixel, row by row from the top.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CostImage {
    width: u32,
    height: u32,
    values: Vec<u64>,
}

impl CostImage {
    /// All zeros. The caller has checked the size against the pixel limit.
    pub fn new(width: u32, height: u32) -> Self {
        CostImage { width, height, values: vec![0; width as usize * height as usize] }
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The work of pixel `(x, y)`.
    pub fn get(&self, x: u32, y: u32) -> u64 {
        self.values[(y * self.width + x) as usize]
    }

    /// Sets the work of pixel `(x, y)`.
    pub fn set(&mut self, x: u32, y: u32, value: u64) {
        self.values[(y * self.width + x) as usize] = value;
    }

    /// All values, row by row.
    pub fn values(&self) -> &[u64] {
        &self.values
    }

    /// The largest value (0 for an image of zeros).
    pub fn max(&self) -> u64 {
        self.values.iter().copied().max().unwrap_or(0)
    }

    /// The sum of all values.
    pub fn total(&self) -> u64 {
        self.values.iter().sum()
    }
}

/// Writes the cost image to `path`, atomically: a `.png` gets the false-colour heatmap with its
/// colour bar, drawn on `scale`; an `.exr` gets the raw counts in all three channels. Returns the
/// scale used.
pub fn write_cost_image(cost: &CostImage, path: &Path, scale: HeatmapScale) -> Result<HeatmapScale, OutputError> {
    let format = OutputFormat::from_path(path)?;
    write_atomically(path, |w| {
        let result = match format {
            OutputFormat::Png => {
                Heatmap::new(cost.width(), cost.height(), cost.values(), scale).to_rgb8().write_to(w, ImageFormat::Png)
            }
            OutputFormat::Exr => {
                let values = cost.values();
                return write_exr_rgb(w, path, cost.width(), cost.height(), |i| [values[i] as f32; 3]);
            }
        };
        result.map_err(|error| OutputError::Encode { path: path.to_owned(), error })
    })?;
    Ok(scale)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exr_keeps_the_raw_counts() {
        let dir = tempfile::tempdir().unwrap();
        let mut cost = CostImage::new(3, 2);
        cost.set(2, 1, 1234);
        cost.set(0, 0, 7);
        assert_eq!((cost.max(), cost.total()), (1234, 1241));
        let path = dir.path().join("cost.exr");
        write_cost_image(&cost, &path, HeatmapScale::log(cost.max())).unwrap();
        let img = image::open(&path).unwrap().to_rgb32f();
        assert_eq!(img.get_pixel(2, 1).0, [1234.0; 3]);
        assert_eq!(img.get_pixel(0, 0).0, [7.0; 3]);
    }

    #[test]
    fn png_is_the_heatmap_with_its_bar() {
        let dir = tempfile::tempdir().unwrap();
        let cost = CostImage::new(64, 48);
        let path = dir.path().join("cost.png");
        write_cost_image(&cost, &path, HeatmapScale::log(0)).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!(img.width(), 64);
        assert!(img.height() > 48, "the colour bar is drawn below the image");
    }
}
