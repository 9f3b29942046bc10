//! The film: linear RGB radiance per pixel, and its conversion to 8-bit sRGB for display (after
//! the exposure and tone map of [`crate::tonemap`]).

use englobe::Vec3;
use englobe_scene::OutputSettings;

/// A `width` x `height` grid of linear RGB values, row by row from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    width: u32,
    height: u32,
    pixels: Vec<Vec3>,
}

impl Film {
    /// A black film. The caller has checked the size against the pixel limit.
    pub fn new(width: u32, height: u32) -> Self {
        Film { width, height, pixels: vec![Vec3::ZERO; width as usize * height as usize] }
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The pixel at column `x`, row `y`.
    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[(y * self.width + x) as usize]
    }

    /// Sets the pixel at column `x`, row `y`.
    pub fn set(&mut self, x: u32, y: u32, value: Vec3) {
        self.pixels[(y * self.width + x) as usize] = value;
    }

    /// All pixels, row by row.
    pub fn pixels(&self) -> &[Vec3] {
        &self.pixels
    }

    /// 8-bit sRGB bytes, three per pixel: values are clamped to `0..=1` and gamma-encoded.
    pub fn to_srgb8(&self) -> Vec<u8> {
        self.pixels.iter().flat_map(|p| [p.x, p.y, p.z]).map(encode_srgb8).collect()
    }

    /// 8-bit sRGB bytes for display, three per pixel: each value exposed and tone mapped as
    /// `settings` say (see [`crate::tonemap`]), then clamped and gamma-encoded. With the default
    /// settings, the bytes of [`Film::to_srgb8`].
    pub fn to_display_srgb8(&self, settings: &OutputSettings) -> Vec<u8> {
        self.pixels
            .iter()
            .flat_map(|p| [p.x, p.y, p.z])
            .map(|v| encode_srgb8(crate::tonemap::display(v, settings)))
            .collect()
    }

    /// Linear `f32` values, three per pixel (for HDR output).
    pub fn to_linear_f32(&self) -> Vec<f32> {
        self.pixels.iter().flat_map(|p| [p.x, p.y, p.z]).collect()
    }
}

/// The sRGB transfer function applied to a linear value, quantised to 8 bits. NaN maps to 0.
pub fn encode_srgb8(linear: f32) -> u8 {
    let c = if linear.is_nan() { 0.0 } else { linear.clamp(0.0, 1.0) };
    let encoded = if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    (encoded * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_encoding_end_points_and_mid_grey() {
        assert_eq!(encode_srgb8(0.0), 0);
        assert_eq!(encode_srgb8(1.0), 255);
        assert_eq!(encode_srgb8(7.0), 255);
        assert_eq!(encode_srgb8(-1.0), 0);
        assert_eq!(encode_srgb8(f32::NAN), 0);
        // sRGB 128/255 is linear ((128/255 + 0.055) / 1.055)^2.4 = 0.2158.
        assert_eq!(encode_srgb8(0.2158), 128);
        assert_eq!(encode_srgb8(0.2140), 127);
    }
}
