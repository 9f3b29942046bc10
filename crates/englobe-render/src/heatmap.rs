//! False colour for the cost AOV: a grid of counts (each pixel's work) mapped through the viridis
//! colormap, with a colour bar and its end values drawn below the image. It sees only the counts,
//! row by row; the cost image that holds them is [`crate::cost`]'s.
//!
//! Viridis is the perceptually uniform colormap of van der Walt, Smith and Firing (2015), designed
//! for matplotlib ("A Better Default Colormap for Matplotlib", SciPy 2015) and released under CC0;
//! 17 of its 256 sRGB entries are kept here and interpolated linearly, which stays within one
//! 8-bit step of the full table. Work spans orders of magnitude between pixels that miss
//! everything and pixels that open many nodes, so the default scale is logarithmic:
//! `position = ln(1 + cost) / ln(1 + max)`.

use image::{Rgb, RgbImage};

/// Entries 0, 16, 32, ..., 240 and 255 of matplotlib's viridis table (sRGB, 0..=1).
const VIRIDIS: [(u8, [f32; 3]); 17] = [
    (0, [0.267004, 0.004874, 0.329415]),
    (16, [0.282327, 0.094955, 0.417331]),
    (32, [0.278826, 0.175490, 0.483397]),
    (48, [0.258965, 0.251537, 0.524736]),
    (64, [0.229739, 0.322361, 0.545706]),
    (80, [0.199430, 0.387607, 0.554642]),
    (96, [0.172719, 0.448791, 0.557885]),
    (112, [0.149039, 0.508051, 0.557250]),
    (128, [0.127568, 0.566949, 0.550556]),
    (144, [0.120638, 0.625828, 0.533488]),
    (160, [0.157851, 0.683765, 0.501686]),
    (176, [0.246070, 0.738910, 0.452024]),
    (192, [0.369214, 0.788888, 0.382914]),
    (208, [0.515992, 0.831158, 0.294279]),
    (224, [0.678489, 0.863742, 0.189503]),
    (240, [0.845561, 0.887322, 0.099702]),
    (255, [0.993248, 0.906157, 0.143936]),
];

/// The viridis colour at `t` in `0..=1` (clamped; NaN maps to 0), as 8-bit sRGB.
pub fn viridis(t: f32) -> [u8; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) } * 255.0;
    let upper = VIRIDIS.iter().position(|&(i, _)| i as f32 >= t).unwrap_or(VIRIDIS.len() - 1).max(1);
    let ((i0, c0), (i1, c1)) = (VIRIDIS[upper - 1], VIRIDIS[upper]);
    let f = ((t - i0 as f32) / (i1 - i0) as f32).clamp(0.0, 1.0);
    std::array::from_fn(|k| ((c0[k] + (c1[k] - c0[k]) * f) * 255.0 + 0.5) as u8)
}

/// How costs map to colours: the value shown brightest, and the kind of scale.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HeatmapScale {
    /// The cost drawn in the brightest colour; larger costs are clamped to it.
    pub max: u64,
    /// Logarithmic (`ln(1 + cost) / ln(1 + max)`) rather than linear (`cost / max`).
    pub log: bool,
}

impl HeatmapScale {
    /// A logarithmic scale up to `max`.
    pub fn log(max: u64) -> Self {
        HeatmapScale { max, log: true }
    }

    /// A linear scale up to `max`.
    pub fn linear(max: u64) -> Self {
        HeatmapScale { max, log: false }
    }

    /// Position of `cost` on the scale, in `0..=1`.
    pub fn position(&self, cost: u64) -> f32 {
        if self.max == 0 {
            return 0.0;
        }
        let c = cost.min(self.max) as f64;
        let p = if self.log { (1.0 + c).ln() / (1.0 + self.max as f64).ln() } else { c / self.max as f64 };
        p as f32
    }

    /// The cost at position `t` of the scale (the inverse of [`Self::position`]), rounded.
    pub fn cost_at(&self, t: f32) -> u64 {
        let m = self.max as f64;
        let t = t.clamp(0.0, 1.0) as f64;
        (if self.log { (1.0 + m).powf(t) - 1.0 } else { t * m }).round() as u64
    }

    /// One line saying what the colours mean.
    pub fn describe(&self) -> String {
        format!(
            "cost = nodes visited + exact tests per pixel; viridis colormap, {} scale, dark = 0, bright = {}{}",
            if self.log { "logarithmic" } else { "linear" },
            self.max,
            if self.log { format!(", middle = {}", self.cost_at(0.5)) } else { String::new() }
        )
    }
}

/// A grid of costs in false colour.
pub struct Heatmap<'a> {
    width: u32,
    height: u32,
    /// `width * height` costs, row by row from the top.
    values: &'a [u64],
    scale: HeatmapScale,
}

/// 3x5 bitmaps of the digits, one row per byte (bit 2 is the left column).
const DIGITS: [[u8; 5]; 10] = [
    [0b111, 0b101, 0b101, 0b101, 0b111],
    [0b010, 0b110, 0b010, 0b010, 0b111],
    [0b111, 0b001, 0b111, 0b100, 0b111],
    [0b111, 0b001, 0b111, 0b001, 0b111],
    [0b101, 0b101, 0b111, 0b001, 0b001],
    [0b111, 0b100, 0b111, 0b001, 0b111],
    [0b111, 0b100, 0b111, 0b101, 0b111],
    [0b111, 0b001, 0b001, 0b001, 0b001],
    [0b111, 0b101, 0b111, 0b101, 0b111],
    [0b111, 0b101, 0b111, 0b001, 0b111],
];

impl<'a> Heatmap<'a> {
    /// The heatmap of the `width` x `height` costs `values` (row by row from the top) on `scale`.
    ///
    /// # Panics
    ///
    /// If `values` does not hold exactly `width * height` costs.
    pub fn new(width: u32, height: u32, values: &'a [u64], scale: HeatmapScale) -> Self {
        assert_eq!(values.len(), width as usize * height as usize, "a {width}x{height} heatmap needs as many costs");
        Heatmap { width, height, values, scale }
    }

    /// The image: the cost in false colour, then below it a colour bar from 0 to the scale's
    /// maximum, with the values at its ends (and middle, where they fit) written under it.
    pub fn to_rgb8(&self) -> RgbImage {
        let (w, h) = (self.width, self.height);
        let glyph = if w >= 256 { 2 } else { 1 };
        let pad = 2 * glyph;
        let bar_height = (h / 20).clamp(6, 24);
        let text_height = 5 * glyph;
        let total = h + pad + bar_height + pad + text_height + pad;
        let mut img = RgbImage::new(w, total);
        for y in 0..h {
            for x in 0..w {
                let cost = self.values[y as usize * w as usize + x as usize];
                img.put_pixel(x, y, Rgb(viridis(self.scale.position(cost))));
            }
        }
        let (x0, x1) = if w > 2 * pad { (pad, w - pad) } else { (0, w) };
        let span = (x1 - x0).max(2) - 1;
        for x in x0..x1 {
            let colour = Rgb(viridis((x - x0) as f32 / span as f32));
            for y in h + pad..h + pad + bar_height {
                img.put_pixel(x, y, colour);
            }
        }
        // Labels: 0 at the left end, the maximum at the right, the middle value centred, each
        // only if it fits without touching its neighbours.
        let y_text = h + pad + bar_height + pad;
        let width_of = |s: &str| s.len() as u32 * 4 * glyph - glyph;
        let (low, high) = ("0".to_owned(), self.scale.max.to_string());
        let mid = self.scale.cost_at(0.5).to_string();
        let mid_x = (x0 + x1) / 2;
        let gap = 3 * glyph;
        if width_of(&low) + gap + width_of(&high) <= x1 - x0 {
            draw_text(&mut img, &low, x0, y_text, glyph);
            draw_text(&mut img, &high, x1 - width_of(&high), y_text, glyph);
            let mid_left = mid_x.saturating_sub(width_of(&mid) / 2);
            if self.scale.max > 1
                && mid_left >= x0 + width_of(&low) + gap
                && mid_left + width_of(&mid) + gap <= x1 - width_of(&high)
            {
                draw_text(&mut img, &mid, mid_left, y_text, glyph);
            }
        }
        img
    }
}

/// Writes the digits of `text` in white with their top-left corner at `(x, y)`, each bitmap pixel
/// `scale` pixels wide. Other characters are skipped.
fn draw_text(img: &mut RgbImage, text: &str, x: u32, y: u32, scale: u32) {
    for (i, ch) in text.chars().enumerate() {
        let Some(bits) = ch.to_digit(10).map(|d| DIGITS[d as usize]) else { continue };
        let left = x + i as u32 * 4 * scale;
        for (row, line) in bits.iter().enumerate() {
            for col in 0..3u32 {
                if line & (0b100 >> col) == 0 {
                    continue;
                }
                for dy in 0..scale {
                    for dx in 0..scale {
                        let (px, py) = (left + col * scale + dx, y + row as u32 * scale + dy);
                        if px < img.width() && py < img.height() {
                            img.put_pixel(px, py, Rgb([255, 255, 255]));
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_end_points_and_middle() {
        assert_eq!(viridis(0.0), [68, 1, 84]);
        assert_eq!(viridis(1.0), [253, 231, 37]);
        assert_eq!(viridis(128.0 / 255.0), [33, 145, 140]);
        assert_eq!(viridis(f32::NAN), viridis(0.0));
        assert_eq!(viridis(7.0), viridis(1.0));
    }

    #[test]
    fn viridis_grows_brighter() {
        let luma = |c: [u8; 3]| 0.2126 * c[0] as f32 + 0.7152 * c[1] as f32 + 0.0722 * c[2] as f32;
        let mut last = -1.0;
        for i in 0..=100 {
            let l = luma(viridis(i as f32 / 100.0));
            assert!(l > last, "at {i}");
            last = l;
        }
    }

    #[test]
    fn log_scale_positions_and_inverse() {
        let s = HeatmapScale::log(999);
        assert_eq!(s.position(0), 0.0);
        assert_eq!(s.position(999), 1.0);
        assert_eq!(s.position(5000), 1.0);
        assert!((s.position(31) - 0.5017).abs() < 1e-3);
        assert_eq!(s.cost_at(0.5), 31);
        assert_eq!(s.cost_at(1.0), 999);
        assert_eq!(HeatmapScale::linear(10).position(5), 0.5);
        assert_eq!(HeatmapScale::log(0).position(3), 0.0);
        assert!(s.describe().contains("logarithmic"), "{}", s.describe());
    }

    #[test]
    fn the_bar_runs_from_dark_to_bright_under_the_image() {
        let mut cost = vec![0; 300 * 200];
        cost[10 * 300 + 10] = 4000;
        let img = Heatmap::new(300, 200, &cost, HeatmapScale::log(4000)).to_rgb8();
        assert_eq!(img.get_pixel(10, 10).0, viridis(1.0));
        assert_eq!(img.get_pixel(0, 0).0, viridis(0.0));
        let bar_y = 200 + 4 + 2;
        assert_eq!(img.get_pixel(4, bar_y).0, viridis(0.0));
        assert_eq!(img.get_pixel(295, bar_y).0, viridis(1.0));
        // Some label pixels are white.
        let white = img.pixels().filter(|p| p.0 == [255, 255, 255]).count();
        assert!(white > 20, "{white}");
    }

    #[test]
    fn tiny_images_get_a_bar_without_labels() {
        let img = Heatmap::new(3, 2, &[0; 6], HeatmapScale::log(123_456)).to_rgb8();
        assert_eq!(img.width(), 3);
        assert!(img.pixels().all(|p| p.0 != [255, 255, 255]));
    }
}
