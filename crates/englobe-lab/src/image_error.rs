//! How far an image is from a reference: the root mean square error of the displayed (sRGB,
//! 8-bit) values, and the mean structural similarity (SSIM: Wang, Bovik, Sheikh and Simoncelli
//! 2004, "Image Quality Assessment: From Error Visibility to Structural Similarity") of their
//! luma, over 8 x 8 windows, the perceptual measure the field uses to say whether a difference
//! shows. Both compare what a viewer sees, so they are taken after the sRGB encoding.

use englobe_render::Film;
use englobe_render::film::encode_srgb8;

/// The difference of an image to its reference.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ImageError {
    /// Root mean square error of the 8-bit sRGB channels, in units of 1/255.
    pub rmse: f64,
    /// Mean SSIM of the luma over 8 x 8 windows: 1 for identical images, lower as structure is lost.
    pub ssim: f64,
}

/// Compares two films of the same size.
pub fn image_error(image: &Film, reference: &Film) -> ImageError {
    assert_eq!((image.width(), image.height()), (reference.width(), reference.height()), "images of one size");
    let srgb = |f: &Film| f.pixels().iter().map(|p| p.to_array().map(encode_srgb8)).collect::<Vec<[u8; 3]>>();
    let (a, b) = (srgb(image), srgb(reference));
    let squared: f64 =
        a.iter().zip(&b).flat_map(|(p, q)| (0..3).map(move |c| (p[c] as f64 - q[c] as f64).powi(2))).sum();
    let rmse = (squared / (3 * a.len()).max(1) as f64).sqrt();
    let luma = |v: &[[u8; 3]]| {
        v.iter().map(|p| 0.299 * p[0] as f64 + 0.587 * p[1] as f64 + 0.114 * p[2] as f64).collect::<Vec<_>>()
    };
    ImageError { rmse, ssim: mean_ssim(&luma(&a), &luma(&b), image.width() as usize, image.height() as usize) }
}

/// Mean SSIM over the 8 x 8 windows that fit (the whole image if it is smaller), with the
/// constants of Wang et al. for a dynamic range of 255.
fn mean_ssim(a: &[f64], b: &[f64], width: usize, height: usize) -> f64 {
    let (c1, c2) = ((0.01f64 * 255.0).powi(2), (0.03f64 * 255.0).powi(2));
    let win = 8.min(width).min(height).max(1);
    let (mut sum, mut windows) = (0.0, 0usize);
    for y0 in (0..=height - win).step_by(win) {
        for x0 in (0..=width - win).step_by(win) {
            let at = |v: &[f64], i: usize| v[(y0 + i / win) * width + x0 + i % win];
            let n = (win * win) as f64;
            let (ma, mb) =
                ((0..win * win).map(|i| at(a, i)).sum::<f64>() / n, (0..win * win).map(|i| at(b, i)).sum::<f64>() / n);
            let (mut va, mut vb, mut cov) = (0.0, 0.0, 0.0);
            for i in 0..win * win {
                let (da, db) = (at(a, i) - ma, at(b, i) - mb);
                va += da * da;
                vb += db * db;
                cov += da * db;
            }
            let (va, vb, cov) = (va / (n - 1.0).max(1.0), vb / (n - 1.0).max(1.0), cov / (n - 1.0).max(1.0));
            sum += ((2.0 * ma * mb + c1) * (2.0 * cov + c2)) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
            windows += 1;
        }
    }
    sum / windows.max(1) as f64
}

#[cfg(test)]
mod tests {
    use englobe::Vec3;

    use super::*;

    fn film(f: impl Fn(u32, u32) -> f32) -> Film {
        let mut film = Film::new(32, 24);
        for y in 0..24 {
            for x in 0..32 {
                film.set(x, y, Vec3::splat(f(x, y)));
            }
        }
        film
    }

    #[test]
    fn identical_images_have_no_error_and_full_similarity() {
        let a = film(|x, y| ((x * 7 + y * 3) % 11) as f32 / 11.0);
        assert_eq!(image_error(&a, &a), ImageError { rmse: 0.0, ssim: 1.0 });
    }

    #[test]
    fn a_constant_offset_costs_rmse_and_noise_costs_structure() {
        let a = film(|x, y| ((x * 7 + y * 3) % 11) as f32 / 11.0 * 0.5);
        // Black against white: every channel 255 apart.
        assert_eq!(image_error(&film(|_, _| 0.0), &film(|_, _| 1.0)).rmse, 255.0);
        let noisy = film(|x, y| ((x * 7 + y * 3) % 11) as f32 / 11.0 * 0.5 + if (x + y) % 2 == 0 { 0.1 } else { -0.1 });
        let e = image_error(&noisy, &a);
        assert!(e.rmse > 5.0 && e.ssim < 0.9, "{e:?}");
        let slight =
            film(|x, y| ((x * 7 + y * 3) % 11) as f32 / 11.0 * 0.5 + if (x + y) % 2 == 0 { 0.004 } else { -0.004 });
        let s = image_error(&slight, &a);
        assert!(s.rmse < e.rmse && s.ssim > e.ssim && s.ssim > 0.95, "{s:?} against {e:?}");
    }
}
