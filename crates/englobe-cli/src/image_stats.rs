//! `englobe info IMAGE.exr [--patch X0,Y0,X1,Y1] [--against REFERENCE.exr]`: the size and mean
//! linear RGB of an OpenEXR image, of a rectangle of its pixels, and how it differs from another
//! renderer's image of the same scene (ratio of means, RMSE, relative MSE), to compare a render
//! with the field's renderers (docs/validation.md). Sums are taken in double precision;
//! non-finite pixels are counted and left out.

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

/// An OpenEXR image's linear RGB, row 0 at the top.
struct RgbImage {
    width: u32,
    height: u32,
    pixels: Vec<[f32; 3]>,
}

fn read_exr(path: &Path) -> anyhow::Result<RgbImage> {
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
    Ok(RgbImage { width, height, pixels })
}

/// How an image differs from a reference of the same size, over the pixels finite in both.
#[derive(Debug, PartialEq)]
struct Difference {
    /// Each channel's mean over the reference's, over the compared pixels.
    mean_ratio: [f64; 3],
    /// The root mean squared difference per channel.
    rmse: [f64; 3],
    /// The mean over pixels and channels of `(a - r)^2 / (r^2 + 0.01)`: squared error relative to
    /// the reference's value, so that dark and bright regions weigh alike (the 0.01 keeps black
    /// pixels from dividing by zero).
    rel_mse: f64,
}

fn difference(a: &[[f32; 3]], reference: &[[f32; 3]]) -> Difference {
    let (mut sum_a, mut sum_r, mut sq, mut rel, mut count) = ([0f64; 3], [0f64; 3], [0f64; 3], 0f64, 0usize);
    for (p, r) in a.iter().zip(reference) {
        if !p.iter().chain(r).all(|c| c.is_finite()) {
            continue;
        }
        for c in 0..3 {
            let (x, y) = (f64::from(p[c]), f64::from(r[c]));
            sum_a[c] += x;
            sum_r[c] += y;
            sq[c] += (x - y) * (x - y);
            rel += (x - y) * (x - y) / (y * y + 0.01);
        }
        count += 1;
    }
    let n = count.max(1) as f64;
    Difference {
        mean_ratio: std::array::from_fn(|c| sum_a[c] / sum_r[c]),
        rmse: sq.map(|s| (s / n).sqrt()),
        rel_mse: rel / (3.0 * n),
    }
}

/// The pixels of `patch`, row by row.
fn patch_pixels(image: &RgbImage, p: Patch) -> Vec<[f32; 3]> {
    (p.y0..p.y1).flat_map(|y| (p.x0..p.x1).map(move |x| image.pixels[(y * image.width + x) as usize])).collect()
}

/// The report on an OpenEXR image: its size and mean, the mean of `patch`, and with `against`
/// how it differs from that reference image (the whole image, and the patch's mean).
pub fn image_info(path: &Path, patch: Option<Patch>, against: Option<&Path>) -> anyhow::Result<String> {
    let image = read_exr(path)?;
    let (width, height) = (image.width, image.height);
    let mut out = String::new();
    let _ = writeln!(out, "image:      {} ({width} x {height}, linear RGB)", path.display());
    let all = Patch { x0: 0, y0: 0, x1: width, y1: height };
    let (m, bad) = mean(&image.pixels, width, all);
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
        let (m, _) = mean(&image.pixels, width, p);
        let _ = writeln!(out, "patch:      x {}..{}, y {}..{} (row 0 at the top)", p.x0, p.x1, p.y0, p.y1);
        let _ = writeln!(out, "patch mean: {:.6} {:.6} {:.6}", m[0], m[1], m[2]);
    }
    if let Some(reference_path) = against {
        let reference = read_exr(reference_path)?;
        anyhow::ensure!(
            (reference.width, reference.height) == (width, height),
            "{} is {} x {} and {} is {width} x {height}: images compare pixel by pixel, at the same size",
            reference_path.display(),
            reference.width,
            reference.height,
            path.display()
        );
        let d = difference(&image.pixels, &reference.pixels);
        let _ = writeln!(out, "against:    {}", reference_path.display());
        let r = d.mean_ratio;
        let _ =
            writeln!(out, "mean ratio: {:.4} {:.4} {:.4} (this image's mean over the reference's)", r[0], r[1], r[2]);
        if let Some(p) = patch {
            let r = difference(&patch_pixels(&image, p), &patch_pixels(&reference, p)).mean_ratio;
            let _ = writeln!(out, "patch ratio: {:.4} {:.4} {:.4}", r[0], r[1], r[2]);
        }
        let e = d.rmse;
        let _ = writeln!(out, "RMSE:       {:.4e} {:.4e} {:.4e}", e[0], e[1], e[2]);
        let _ = writeln!(out, "rel. MSE:   {:.4e} (mean of (a - ref)^2 / (ref^2 + 0.01))", d.rel_mse);
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

    #[test]
    fn differences_follow_their_formulas() {
        let reference = [[1.0, 2.0, 0.0], [3.0, 2.0, 0.0], [f32::INFINITY, 1.0, 1.0]];
        let image = [[1.5, 2.0, 0.1], [2.5, 2.0, 0.1], [9.0, 9.0, 9.0]];
        let d = difference(&image, &reference);
        // The third pixel is not finite in the reference: left out.
        assert_eq!(d.mean_ratio[0], 1.0);
        assert_eq!(d.mean_ratio[1], 1.0);
        assert!(d.mean_ratio[2].is_infinite(), "a black reference channel has no finite ratio");
        assert!((d.rmse[0] - 0.5).abs() < 1e-12 && d.rmse[1] == 0.0 && (d.rmse[2] - 0.1).abs() < 1e-7);
        let rel = (0.25 / 1.01 + 0.25 / 9.01 + 2.0 * 0.01f64 / 0.01) / 6.0;
        assert!((d.rel_mse - rel).abs() < 1e-6, "{} against {rel}", d.rel_mse);
        let same = difference(&reference[..2], &reference[..2]);
        assert_eq!((same.rmse, same.rel_mse), ([0.0; 3], 0.0));
    }
}
