//! The path tracer's share of "fewer rays" (`englobe experiment fewer-rays` on a path-traced
//! scene): adaptive sampling to a noise threshold (englobe-render's `adaptive`) against uniform
//! sampling, both measured against a converged reference, and the question asked the seed's way:
//! how many samples does uniform sampling need to reach the error adaptive sampling reaches?
//!
//! The reference takes `reference_samples` per pixel with another seed than the renders it
//! judges: its noise is then independent of theirs (a render's first `n` samples are the
//! reference's own otherwise, and the error would shrink by sharing them); its own noise, and the
//! rounding of both images to 8 bits, put a floor under every error, which is why it takes four
//! times the samples of the most sampled render it judges. The uniform renders take 16, 32, ...
//! up to a quarter of the reference (at least 16 and 32); the samples uniform sampling needs for an error
//! are read off their curve, interpolated in log-log space between the two renders around it
//! (Monte Carlo error falls as a power of the samples, `1 / sqrt(n)` for pure noise), and
//! divided by the mean samples adaptive sampling took: the ratio of samples at equal error.

use std::fmt::Write as _;
use std::time::Instant;

use englobe::World;
use englobe_render::{RayKind, RenderOutput, Renderer};
use englobe_scene::{NoiseAllocation, Scene};

use crate::error::LabError;
use crate::image_error::{ImageError, image_error};
use crate::report::grouped;

/// Samples per pixel of the reference, by default.
pub const REFERENCE_PATH_SAMPLES: u32 = 4096;

/// Noise thresholds measured by default.
pub const DEFAULT_NOISE_THRESHOLDS: [f32; 4] = [0.05, 0.03, 0.02, 0.01];

/// The first pass of adaptive sampling, and the fewest samples of the uniform renders.
pub const FIRST_PASS: u32 = 16;

/// One render of the comparison.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SamplingRow {
    /// The scene file.
    pub scene: String,
    /// `uniform, reference`, `uniform`, `adaptive, even` or `adaptive, mse` (the allocation).
    pub method: String,
    /// Samples per pixel, or the noise threshold.
    pub setting: String,
    /// Samples taken, over the image.
    pub samples_total: u64,
    /// Samples per pixel, on average.
    pub samples_mean: f64,
    /// Rays cast, all kinds.
    pub rays: u64,
    /// Exact tests, all kinds.
    pub exact_tests: u64,
    /// Seconds spent rendering (counting on).
    pub seconds: f64,
    /// Against the reference.
    pub error: ImageError,
    /// Adaptive rows: the samples per pixel uniform sampling needs for the same RMSE (`None`
    /// outside the uniform renders' range).
    pub uniform_equivalent: Option<f64>,
    /// Adaptive rows: `uniform_equivalent` over `samples_mean`, how many times fewer samples
    /// adaptive sampling takes for its error.
    pub ratio: Option<f64>,
}

/// The samples per pixel uniform sampling needs for an RMSE of `rmse`, from its renders
/// `(samples, rmse)` in increasing samples: interpolated in log-log space between the two
/// renders whose errors bracket it; `None` outside their range.
pub fn uniform_samples_at(rmse: f64, uniform: &[(u32, f64)]) -> Option<f64> {
    uniform.windows(2).find_map(|w| {
        let ((n0, e0), (n1, e1)) = (w[0], w[1]);
        if !(rmse <= e0 && rmse >= e1) || e0 <= 0.0 || e1 <= 0.0 || rmse <= 0.0 {
            return None;
        }
        if e0 == e1 {
            return Some(n0 as f64);
        }
        let t = (rmse.ln() - e0.ln()) / (e1.ln() - e0.ln());
        Some(((n0 as f64).ln() + t * ((n1 as f64).ln() - (n0 as f64).ln())).exp())
    })
}

/// Runs the comparison on `scene` (already at the size measured) through `world`; `progress`
/// gets a line per render.
pub fn sampling_rows(
    name: &str,
    scene: &Scene,
    world: &World,
    reference_samples: u32,
    thresholds: &[f32],
    pool: &rayon::ThreadPool,
    progress: &mut dyn FnMut(String),
) -> Result<Vec<SamplingRow>, LabError> {
    let render = |scene: &Scene| -> Result<(RenderOutput, f64), LabError> {
        let start = Instant::now();
        let out = pool.install(|| Renderer::new(scene, world).count_work(true).render())?;
        Ok((out, start.elapsed().as_secs_f64()))
    };
    let pixels = (scene.image.width as u64 * scene.image.height as u64).max(1);
    let row = |method: &str, setting: String, out: &RenderOutput, seconds: f64, error: ImageError| {
        let samples_total = out.stats.kind(RayKind::Primary).rays;
        let total = out.stats.total();
        SamplingRow {
            scene: name.to_owned(),
            method: method.to_owned(),
            setting,
            samples_total,
            samples_mean: samples_total as f64 / pixels as f64,
            rays: total.rays,
            exact_tests: total.exact_tests,
            seconds,
            error,
            uniform_equivalent: None,
            ratio: None,
        }
    };
    let mut uniform = scene.clone();
    uniform.image.noise_threshold = 0.0;
    let mut reference_scene = uniform.clone();
    reference_scene.image.samples = reference_samples;
    reference_scene.image.seed = scene.image.seed.wrapping_add(1);
    progress(format!("{name}: uniform sampling, reference, {reference_samples} samples"));
    let (reference, seconds) = render(&reference_scene)?;
    let mut rows = vec![row(
        "uniform, reference",
        format!("{reference_samples} spp"),
        &reference,
        seconds,
        image_error(&reference.film, &reference.film),
    )];
    let mut curve = Vec::new();
    let mut samples = FIRST_PASS;
    while samples <= (reference_samples / 4).max(2 * FIRST_PASS) {
        progress(format!("{name}: uniform sampling, {samples} samples"));
        uniform.image.samples = samples;
        let (out, seconds) = render(&uniform)?;
        let error = image_error(&out.film, &reference.film);
        curve.push((samples, error.rmse));
        rows.push(row("uniform", format!("{samples} spp"), &out, seconds, error));
        samples *= 2;
    }
    for allocation in [NoiseAllocation::Even, NoiseAllocation::Mse] {
        let method = format!("adaptive, {}", allocation.name());
        for &threshold in thresholds {
            progress(format!("{name}: adaptive sampling ({}), threshold {threshold}", allocation.name()));
            let mut adaptive = scene.clone();
            adaptive.image.samples = reference_samples;
            adaptive.image.noise_threshold = threshold;
            adaptive.image.noise_allocation = allocation;
            adaptive.image.min_samples = Some(FIRST_PASS.min(reference_samples));
            let (out, seconds) = render(&adaptive)?;
            let error = image_error(&out.film, &reference.film);
            let mut r = row(&method, format!("{threshold}"), &out, seconds, error);
            r.uniform_equivalent = uniform_samples_at(error.rmse, &curve);
            r.ratio = r.uniform_equivalent.map(|n| n / r.samples_mean);
            rows.push(r);
        }
    }
    Ok(rows)
}

/// The table of the rows: samples, rays, exact tests, time, error, and for adaptive rows the
/// uniform samples at the same error and the ratio.
pub fn sampling_table(rows: &[SamplingRow]) -> String {
    let mut s = String::new();
    if rows.is_empty() {
        return s;
    }
    let _ = writeln!(
        s,
        "\n{:<24} {:<18} {:>9} {:>8} {:>13} {:>13} {:>7} {:>6} {:>7} {:>12} {:>6}",
        "scene", "method", "setting", "spp", "rays", "exact tests", "s", "RMSE", "SSIM", "uniform spp", "ratio"
    );
    for r in rows {
        let (equivalent, ratio) = match (r.method.as_str(), r.uniform_equivalent, r.ratio) {
            (_, Some(n), Some(x)) => (format!("{n:.0}"), format!("{x:.2}x")),
            (m, _, _) if m.starts_with("adaptive") => ("out of range".to_owned(), "-".to_owned()),
            _ => (String::new(), String::new()),
        };
        let line = format!(
            "{:<24} {:<18} {:>9} {:>8.1} {:>13} {:>13} {:>7.3} {:>6.2} {:>7.4} {:>12} {:>6}",
            r.scene.trim_start_matches("scenes/"),
            r.method,
            r.setting,
            r.samples_mean,
            grouped(r.rays),
            grouped(r.exact_tests),
            r.seconds,
            r.error.rmse,
            r.error.ssim,
            equivalent,
            ratio
        );
        let _ = writeln!(s, "{}", line.trim_end());
    }
    s
}

#[cfg(test)]
mod tests {
    use englobe::AccelKind;

    use super::*;
    use crate::measure::{build, thread_pool};

    #[test]
    fn samples_at_an_error_on_a_power_law_are_found_exactly() {
        // RMSE = 8 / sqrt(n): the curve of pure noise.
        let curve: Vec<(u32, f64)> = [16, 32, 64, 128].iter().map(|&n| (n, 8.0 / (n as f64).sqrt())).collect();
        for n in [16.0, 20.0, 45.0, 100.0, 128.0] {
            let at = uniform_samples_at(8.0 / f64::sqrt(n), &curve).unwrap();
            assert!((at - n).abs() < 1e-9 * n, "{n}: {at}");
        }
        assert_eq!(uniform_samples_at(3.0, &curve), None, "above the fewest samples' error");
        assert_eq!(uniform_samples_at(0.5, &curve), None, "below the most samples' error");
    }

    /// The default scene path traced, small: the sky is flat, the spheres and ground noisy.
    fn small_scene() -> Scene {
        let mut s = englobe_scene::parse_scene(englobe_render::DEFAULT_SCENE, "default.toml".as_ref()).unwrap();
        (s.image.width, s.image.height) = (40, 30);
        s.image.integrator = englobe_scene::IntegratorKind::Path;
        s
    }

    #[test]
    fn adaptive_images_are_the_same_bytes_on_one_and_two_threads() {
        let mut s = small_scene();
        s.image.samples = 64;
        s.image.noise_threshold = 0.02;
        let (world, _) = build(&s, AccelKind::BvhWide).unwrap();
        let film = |threads: u32| {
            let out = thread_pool(Some(threads)).unwrap().install(|| Renderer::new(&s, &world).render()).unwrap();
            (out.film.to_srgb8(), out.film.to_linear_f32().iter().map(|v| v.to_bits()).collect::<Vec<_>>())
        };
        assert_eq!(film(1), film(2));
    }

    #[test]
    fn adaptive_sampling_reaches_an_error_with_fewer_samples_than_uniform() {
        let s = small_scene();
        let (world, _) = build(&s, AccelKind::BvhWide).unwrap();
        let pool = thread_pool(Some(2)).unwrap();
        let rows = sampling_rows("small", &s, &world, 256, &[0.03], &pool, &mut |_| {}).unwrap();
        let methods: Vec<&str> = rows.iter().map(|r| r.method.as_str()).collect();
        assert_eq!(methods, ["uniform, reference", "uniform", "uniform", "uniform", "adaptive, even", "adaptive, mse"]);
        let uniform: Vec<&SamplingRow> = rows.iter().filter(|r| r.method == "uniform").collect();
        assert_eq!(uniform.iter().map(|r| r.samples_mean).collect::<Vec<_>>(), [16.0, 32.0, 64.0]);
        assert!(uniform.windows(2).all(|w| w[1].error.rmse < w[0].error.rmse), "more samples, less error");
        eprintln!("{}", sampling_table(&rows));
        let adaptive = &rows[rows.len() - 2];
        let ratio = adaptive.ratio.expect("its error lies within the uniform renders'");
        // The sky (a third of the image) stops at the first pass; the rest takes about what uniform
        // sampling takes. The figures are fixed by the seed: 1.22 times fewer samples.
        assert!(ratio > 1.15, "{ratio}: {}", sampling_table(&rows));
        assert!(adaptive.samples_mean < adaptive.uniform_equivalent.unwrap());
        let table = sampling_table(&rows);
        assert!(table.contains("adaptive") && table.contains(&format!("{ratio:.2}x")), "{table}");
        // The mse allocation gives the noisy ground samples in proportion to its noise, not its
        // square: fewer samples again for its error (1.32 times fewer, by the seed).
        let mse = rows.last().unwrap();
        let mse_ratio = mse.ratio.expect("its error lies within the uniform renders'");
        assert!(mse_ratio > ratio, "mse {mse_ratio} against even {ratio}: {table}");
        assert!(mse.samples_mean < adaptive.samples_mean, "the same threshold, fewer samples: {table}");
    }
}
