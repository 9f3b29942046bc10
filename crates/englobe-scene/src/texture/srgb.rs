//! The sRGB transfer function (IEC 61966-2-1:1999), both ways, with a table for 8-bit texels so
//! that a lookup costs no `powf`.

use std::sync::OnceLock;

/// Linear value of the sRGB-encoded value `c` in `0..=1`.
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// sRGB encoding of the linear value `c` in `0..=1`.
#[inline]
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.0031308 { c * 12.92 } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

/// Linear value of each 8-bit sRGB code.
pub(crate) fn srgb8_table() -> &'static [f32; 256] {
    static TABLE: OnceLock<[f32; 256]> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values() {
        // 188/255 is the 8-bit code closest to linear one half.
        assert!((srgb_to_linear(188.0 / 255.0) - 0.5029).abs() < 1e-3);
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        // Below the knee the curve is the straight line c / 12.92.
        assert!((srgb_to_linear(0.04) - 0.04 / 12.92).abs() < 1e-9);
        assert!((srgb8_table()[128] - 0.2158605).abs() < 1e-5);
        for i in 0..=255 {
            let c = i as f32 / 255.0;
            assert!((linear_to_srgb(srgb_to_linear(c)) - c).abs() < 1e-5, "{i}");
        }
    }
}
