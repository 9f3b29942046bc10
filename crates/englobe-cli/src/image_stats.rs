//! `englobe info IMAGE.exr [--patch X0,Y0,X1,Y1]`: the size and mean linear RGB of an OpenEXR
//! image, and of a rectangle of its pixels, to compare a render with other renderers' figures
//! (docs/validation.md). Means are taken in double precision over every pixel; non-finite pixels
//! are counted and left out.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Context;

/// A rectangle of pixels, `[x0, x1) x [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Patch {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

/// Parses `X0,Y0,X1,Y1` (the first corner inclusive, the second exclusive).
pub fn parse_patch(text: &str) -> Result<Patch, String> {
    let v: Vec<u32> = text
        .split(',')
        .map(|s| s.trim().parse::<u32>().map_err(|_| format!("\"{s}\" is not a pixel coordinate")))
        .collect::<Result<_, _>>()?;
    let [x0, y0, x1, y1] = v[..] else {
        return Err(format!("expected X0,Y0,X1,Y1 (four pixel coordinates), found {} numbers", v.len()));
    };
    if x0 >= x1 || y0 >= y1 {
        return Err(format!("the patch {x0},{y0},{x1},{y1} is empty: expected X0 < X1 and Y0 < Y1"));
    }
    Ok(Patch { x0, y0, x1, y1 })
}

/// Mean RGB over the pixels of `patch` that are finite, and how many were not.
fn mean(pixels: &[[f32; 3]], width: u32, patch: Patch) -> ([f64; 3], usize) {
    let (mut sum, mut count, mut bad) = ([0f64; 3], 0usize, 0usize);
    for y in patch.y0..patch.y1 {
        for x in patch.x0..patch.x1 {
            let p = pixels[(y * width + x) as usize];
            if p.iter().all(|c| c.is_finite()) {
                (0..3).for_each(|c| sum[c] += f64::from(p[c]));
                count += 1;
            } else {
                bad += 1;
            }
        }
    }
    (sum.map(|s| s / count.max(1) as f64), bad)
}

/// The report on an OpenEXR image.
pub fn image_info(path: &Path, patch: Option<Patch>) -> anyhow::Result<String> {
    use exr::prelude::*;
    let image = read_first_rgba_layer_from_file(
        path,
        |resolution, _| (resolution.width(), vec![[0f32; 3]; resolution.width() * resolution.height()]),
        |(width, pixels), position, (r, g, b, _a): (f32, f32, f32, f32)| {
            pixels[position.y() * *width + position.x()] = [r, g, b];
        },
    )
    .with_context(|| format!("{}: cannot read it as an OpenEXR image", path.display()))?;
    let (width, pixels) = image.layer_data.channel_data.pixels;
    let (width, height) = (width as u32, (pixels.len() / width.max(1)) as u32);
    let mut out = String::new();
    let _ = writeln!(out, "image:      {} ({width} x {height}, linear RGB)", path.display());
    let all = Patch { x0: 0, y0: 0, x1: width, y1: height };
    let (m, bad) = mean(&pixels, width, all);
    let _ = writeln!(out, "mean RGB:   {:.6} {:.6} {:.6}", m[0], m[1], m[2]);
    if bad > 0 {
        let _ = writeln!(out, "non-finite: {bad} pixels (left out of the means)");
    }
    if let Some(p) = patch {
        anyhow::ensure!(
            p.x1 <= width && p.y1 <= height,
            "the patch {},{},{},{} is not inside the {width} x {height} image",
            p.x0,
            p.y0,
            p.x1,
            p.y1
        );
        let (m, _) = mean(&pixels, width, p);
        let _ = writeln!(out, "patch:      x {}..{}, y {}..{} (row 0 at the top)", p.x0, p.x1, p.y0, p.y1);
        let _ = writeln!(out, "patch mean: {:.6} {:.6} {:.6}", m[0], m[1], m[2]);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patches_are_parsed_or_refused_with_the_reason() {
        assert_eq!(parse_patch("1, 2,30,40"), Ok(Patch { x0: 1, y0: 2, x1: 30, y1: 40 }));
        assert!(parse_patch("1,2,3").unwrap_err().contains("four"));
        assert!(parse_patch("5,2,3,9").unwrap_err().contains("empty"));
        assert!(parse_patch("a,2,3,9").unwrap_err().contains("\"a\""));
    }

    #[test]
    fn means_leave_out_non_finite_pixels() {
        let pixels = [[1.0, 2.0, 3.0], [3.0, 4.0, 5.0], [f32::NAN, 0.0, 0.0], [5.0, 6.0, 7.0]];
        let (m, bad) = mean(&pixels, 2, Patch { x0: 0, y0: 0, x1: 2, y1: 2 });
        assert_eq!((m, bad), ([3.0, 4.0, 5.0], 1));
        let (m, _) = mean(&pixels, 2, Patch { x0: 1, y0: 0, x1: 2, y1: 1 });
        assert_eq!(m, [3.0, 4.0, 5.0]);
    }
}
