//! From linear radiance to display values, for 8-bit images only: the exposure (a factor of
//! `2^EV`), then a tone map, then the sRGB encoding (in [`crate::film`]). OpenEXR images keep the
//! linear radiance untouched.
//!
//! The filmic curve is Narkowicz's fit of the ACES reference rendering and output transforms
//! (RRT and ODT for sRGB displays): K. Narkowicz, "ACES Filmic Tone Mapping Curve", 2016,
//! `f(x) = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)`, clipped to `0..=1`. Its data was
//! pre-exposed so that 1 maps to about 0.8, which keeps images about as bright as without it. It
//! is monotonic for `x >= 0` (its derivative's numerator, `1.408 x² + 0.7028 x + 0.0042`, is
//! positive), maps 0 to 0 and compresses highlights smoothly instead of clipping them.

use englobe_scene::{OutputSettings, ToneMap};

/// Narkowicz's ACES fit at `x` (exposed linear radiance), in `0..=1`; NaN and negative values
/// give 0.
pub fn filmic(x: f32) -> f32 {
    if !(x > 0.0) {
        return 0.0;
    }
    if x.is_infinite() {
        return 1.0;
    }
    let (a, b, c, d, e) = (2.51, 0.03, 2.43, 0.59, 0.14);
    ((x * (a * x + b)) / (x * (c * x + d) + e)).clamp(0.0, 1.0)
}

/// The display value (before sRGB encoding, in `0..=1`) of one linear channel value.
pub fn display(linear: f32, settings: &OutputSettings) -> f32 {
    let exposed = linear * exposure_factor(settings.exposure);
    match settings.tonemap {
        ToneMap::None => exposed,
        ToneMap::Filmic => filmic(exposed),
    }
}

/// `2^ev`, the factor of an exposure of `ev` stops.
pub fn exposure_factor(ev: f32) -> f32 {
    ev.exp2()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_filmic_curve_is_monotonic_from_zero_to_one() {
        assert_eq!(filmic(0.0), 0.0);
        assert_eq!(filmic(-3.0), 0.0);
        assert_eq!(filmic(f32::NAN), 0.0);
        assert_eq!(filmic(f32::INFINITY), 1.0);
        // Hand values: f(1) = 2.54 / 3.16, f(0.18) = 0.086724 / 0.324932.
        assert!((filmic(1.0) - 2.54 / 3.16).abs() < 1e-6);
        assert!((filmic(0.18) - 0.086_724 / 0.324_932).abs() < 1e-6);
        let mut last = 0.0;
        for i in 1..100_000 {
            let x = i as f32 * 1e-3;
            let y = filmic(x);
            assert!(y >= last && y <= 1.0, "f({x}) = {y} after {last}");
            last = y;
        }
        assert_eq!(filmic(1e6), 1.0);
    }

    #[test]
    fn one_stop_more_doubles_linear_values() {
        let at = |ev: f32| OutputSettings { exposure: ev, ..OutputSettings::default() };
        for v in [0.0f32, 0.01, 0.3, 7.5] {
            assert_eq!(display(v, &at(1.0)), 2.0 * display(v, &at(0.0)));
            assert_eq!(display(v, &at(-2.0)), 0.25 * v);
        }
        assert_eq!(display(0.3, &OutputSettings::default()), 0.3, "no exposure, no tone map: the value itself");
        let filmic_at = OutputSettings { exposure: 1.0, tonemap: ToneMap::Filmic, exr_half: false };
        assert_eq!(display(0.25, &filmic_at), filmic(0.5));
    }
}
