//! MTL colour statements (`Ka`, `Kd`, `Ks`, `Ke`, `Tf`) in the three forms the MTL specification
//! allows (Wavefront, "MTL material format", Advanced Visualizer 4.2 manual, appendix B1):
//!
//! - `Kd r [g b]`: RGB; `g` and `b` are optional and equal to `r` when left out;
//! - `Kd xyz x [y z]`: CIE XYZ, `y` and `z` equal to `x` when left out, converted here to linear
//!   sRGB (Rec. 709 primaries, D65 white; IEC 61966-2-1);
//! - `Kd spectral file.rfl [factor]`: a reflectance curve in a file of its own, `factor`
//!   (default 1) scaling it. englobe does not read `.rfl` files: the statement is reported and
//!   the colour keeps its default.
//!
//! `tobj` reads only the first form, with all three numbers (and panicked on two up to version
//! 4.0.4), so the library's text is rewritten to that form before `tobj` sees it
//! ([`super::mtl::scan`]).

use englobe::Vec3;

/// A colour statement's value.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum MtlColor {
    /// Linear RGB (from either numeric form).
    Rgb(Vec3),
    /// `spectral FILE [factor]`, which englobe does not read.
    Spectral {
        /// The `.rfl` file.
        file: String,
        /// Its scale.
        factor: f32,
    },
}

/// CIE XYZ to linear sRGB (IEC 61966-2-1, the inverse of its RGB-to-XYZ matrix), rows.
const XYZ_TO_RGB: [[f32; 3]; 3] = [[3.2406, -1.5372, -0.4986], [-0.9689, 1.8758, 0.0415], [0.0557, -0.2040, 1.0570]];

fn number(word: &str, what: &str) -> Result<f32, String> {
    match word.parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(format!("{what} must be finite, found `{word}`")),
        Err(_) => Err(format!("expected {what}, found `{word}`")),
    }
}

/// One to three numbers, the missing ones equal to the first.
fn triple(words: &[&str], what: &str) -> Result<Vec3, String> {
    match words {
        [] => Err(format!("expected {what}, found nothing")),
        [a] => Ok(Vec3::splat(number(a, what)?)),
        // Two numbers are not a form of the specification; a comment after three is ignored, as
        // `tobj` and other readers do.
        [_, _] => Err(format!("expected {what}: one number or three, found two")),
        [a, b, c, ..] => Ok(Vec3::new(number(a, what)?, number(b, what)?, number(c, what)?)),
    }
}

/// Parses the rest of a colour statement (the words after its keyword).
pub(super) fn parse_color(rest: &str) -> Result<MtlColor, String> {
    let words: Vec<&str> = rest.split_whitespace().take_while(|w| !w.starts_with('#')).collect();
    match words.first().copied() {
        Some("spectral") => {
            let file = words.get(1).ok_or("expected `spectral FILE [factor]`, found no file")?;
            let factor = words.get(2).map_or(Ok(1.0), |w| number(w, "a factor after the spectral file"))?;
            Ok(MtlColor::Spectral { file: (*file).to_owned(), factor })
        }
        Some("xyz") => {
            let xyz = triple(&words[1..], "CIE XYZ values (`xyz x [y z]`)")?;
            let row = |r: [f32; 3]| Vec3::from(r).dot(xyz);
            Ok(MtlColor::Rgb(Vec3::new(row(XYZ_TO_RGB[0]), row(XYZ_TO_RGB[1]), row(XYZ_TO_RGB[2]))))
        }
        _ => Ok(MtlColor::Rgb(triple(&words, "a colour (`r [g b]`, `xyz x [y z]` or `spectral FILE [factor]`)")?)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgb_with_one_or_three_numbers() {
        assert_eq!(parse_color("0.1 0.2 0.3"), Ok(MtlColor::Rgb(Vec3::new(0.1, 0.2, 0.3))));
        assert_eq!(parse_color("0.4"), Ok(MtlColor::Rgb(Vec3::splat(0.4))), "g and b default to r");
        assert_eq!(parse_color("0.63 0.065 0.05 # Red"), Ok(MtlColor::Rgb(Vec3::new(0.63, 0.065, 0.05))));
        assert!(parse_color("0.5 0.5").unwrap_err().contains("found two"));
        assert!(parse_color("").unwrap_err().contains("found nothing"));
        assert!(parse_color("0.5 x 1").unwrap_err().contains("found `x`"));
        assert!(parse_color("inf").unwrap_err().contains("finite"));
    }

    #[test]
    fn xyz_is_converted_to_linear_srgb() {
        // D65 white (X 0.9505, Y 1, Z 1.089) is RGB (1, 1, 1) to the matrix's four digits.
        let MtlColor::Rgb(white) = parse_color("xyz 0.9505 1.0 1.089").unwrap() else { panic!() };
        assert!((white - Vec3::ONE).abs().max_element() < 2e-3, "{white}");
        // One number: x = y = z.
        let MtlColor::Rgb(c) = parse_color("xyz 0.5").unwrap() else { panic!() };
        assert!((c - Vec3::new(0.6024, 0.4742, 0.4544)).abs().max_element() < 1e-4, "{c}");
        assert!(parse_color("xyz").is_err());
    }

    #[test]
    fn spectral_keeps_its_file_and_factor() {
        assert_eq!(parse_color("spectral ident.rfl"), Ok(MtlColor::Spectral { file: "ident.rfl".into(), factor: 1.0 }));
        assert_eq!(parse_color("spectral a.rfl 0.5"), Ok(MtlColor::Spectral { file: "a.rfl".into(), factor: 0.5 }));
        assert!(parse_color("spectral").is_err());
        assert!(parse_color("spectral a.rfl x").is_err());
    }
}
