//! The seed report's other family of speed-ups (its section 2.1): casting fewer rays, measured the
//! seed's way: rays cast and exact tests per kind of ray, the time, and what the image loses
//! against a full render (see [`crate::image_error`]).
//!
//! Two methods are measured on Whitted scenes:
//!
//! - adaptive depth (Hall and Greenberg 1983, "A Testbed for Realistic Image Synthesis"):
//!   secondary rays whose contribution to the pixel would fall below a threshold are not cast
//!   (the scene's `min_contribution`, see englobe-render's `whitted`), against the full depth;
//! - adaptive supersampling (Whitted 1980, with Mitchell's 1987 contrast; englobe-render's
//!   `supersample`): corners first, cut where they differ, against uniform jittered
//!   supersampling at 4 and 16 samples, all measured against 64 uniform samples per pixel.
//!
//! On path-traced scenes (whose depth is a matter of Russian roulette, and whose noise would make
//! every square look like an edge) a third: adaptive sampling to a noise threshold against uniform
//! sampling, at equal error (see [`crate::fewer_samples`]). On textured Whitted scenes a fourth,
//! the generalised rays: ray cones filtering the textures against point sampling, at equal error
//! (see [`crate::ray_cones`]).

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use englobe::AccelKind;
use englobe_render::supersample::AdaptiveSupersampling;
use englobe_render::{RayKind, RenderStats, Renderer};
use englobe_scene::{IntegratorKind, Scene, load_scene};

use crate::error::LabError;
use crate::fewer_samples::{
    DEFAULT_NOISE_THRESHOLDS, REFERENCE_PATH_SAMPLES, SamplingRow, sampling_rows, sampling_table,
};
use crate::image_error::{ImageError, image_error};
use crate::measure::{build, thread_pool};
use crate::ray_cones::{ConeRow, cone_rows, cone_table};
use crate::report::grouped;

/// The scenes measured by default, relative to the repository's root: the seed report's four
/// tests, the glass and mirror scenes (where rays branch most), the Sponza, the path-traced
/// Cornell box, and a textured ground receding to the horizon (for the ray cones).
pub const DEFAULT_SCENES: [&str; 9] = [
    "scenes/seed/test1.toml",
    "scenes/seed/test2.toml",
    "scenes/seed/test3.toml",
    "scenes/seed/test4.toml",
    "scenes/glass.toml",
    "scenes/mirrors.toml",
    "scenes/sponza.toml",
    "scenes/cornell-box-path.toml",
    "scenes/textured-ground.toml",
];

/// The adaptive-depth thresholds measured by default.
pub const DEFAULT_THRESHOLDS: [f32; 4] = [0.1, 0.03, 0.01, 0.003];

/// Samples per pixel of the anti-aliasing reference.
pub const REFERENCE_SAMPLES: u32 = 64;

/// Uniform supersampling rates compared with the adaptive one.
pub const UNIFORM_SAMPLES: [u32; 2] = [4, 16];

/// Adaptive supersampling settings measured: (contrast, maximum level).
pub const ADAPTIVE_SUPERSAMPLING: [(f32, u32); 3] = [(0.1, 2), (0.05, 3), (0.02, 3)];

/// What to measure.
#[derive(Clone, Debug)]
pub struct FewerRaysOptions {
    /// Scene files (default: [`DEFAULT_SCENES`]).
    pub scenes: Vec<PathBuf>,
    /// The longer side of the images, the other following the scene's aspect ratio (default 320).
    pub size: u32,
    /// Adaptive-depth thresholds (default: [`DEFAULT_THRESHOLDS`]).
    pub thresholds: Vec<f32>,
    /// Worker threads (default: all cores).
    pub threads: Option<u32>,
    /// The longer side of path-traced scenes' images (default 128: their reference takes
    /// thousands of samples per pixel).
    pub path_size: u32,
    /// Samples per pixel of path-traced scenes' reference (default [`REFERENCE_PATH_SAMPLES`]);
    /// also adaptive sampling's maximum.
    pub reference_samples: u32,
    /// Noise thresholds of adaptive sampling (default: [`DEFAULT_NOISE_THRESHOLDS`]).
    pub noise_thresholds: Vec<f32>,
}

impl Default for FewerRaysOptions {
    fn default() -> Self {
        FewerRaysOptions {
            scenes: DEFAULT_SCENES.iter().map(PathBuf::from).collect(),
            size: 320,
            thresholds: DEFAULT_THRESHOLDS.to_vec(),
            threads: None,
            path_size: 128,
            reference_samples: REFERENCE_PATH_SAMPLES,
            noise_thresholds: DEFAULT_NOISE_THRESHOLDS.to_vec(),
        }
    }
}

/// One render of one scene.
#[derive(Clone, Debug, serde::Serialize)]
pub struct FewerRaysRow {
    /// The scene file.
    pub scene: String,
    /// `full depth` (the reference of `adaptive depth`), `adaptive depth`, `uniform, reference`
    /// (the reference of `uniform` and `adaptive ss`), `uniform` or `adaptive ss` (adaptive
    /// supersampling).
    pub method: String,
    /// The setting: the scene's maximum depth, the threshold, the samples per pixel, or the
    /// contrast and maximum level.
    pub setting: String,
    /// Rays cast per kind: primary, shadow, reflected, refracted.
    pub rays: [u64; 4],
    /// Exact tests, all kinds.
    pub exact_tests: u64,
    /// Seconds spent rendering (with counting on, as for every row).
    pub seconds: f64,
    /// Against the reference (zero for the reference itself).
    pub error: ImageError,
}

/// The experiment's rows.
#[derive(Clone, Debug, serde::Serialize)]
pub struct FewerRays {
    /// Every render of a Whitted scene.
    pub rows: Vec<FewerRaysRow>,
    /// Every render of a path-traced scene: adaptive sampling against uniform sampling.
    pub sampling: Vec<SamplingRow>,
    /// Every render of a textured Whitted scene: ray cones against point-sampled textures.
    pub cones: Vec<ConeRow>,
}

/// Runs the experiment; `progress` gets a line per render.
pub fn run_fewer_rays(options: &FewerRaysOptions, progress: &mut dyn FnMut(String)) -> Result<FewerRays, LabError> {
    let pool = thread_pool(options.threads)?;
    let mut out = FewerRays { rows: Vec::new(), sampling: Vec::new(), cones: Vec::new() };
    for path in &options.scenes {
        let name = path.display().to_string();
        let mut scene = load_scene(path)?;
        let path_traced = scene.image.integrator != IntegratorKind::Whitted;
        let (w, h) = (scene.image.width as f64, scene.image.height as f64);
        let scale = if path_traced { options.path_size } else { options.size } as f64 / w.max(h);
        scene.image.width = ((w * scale).round() as u32).max(1);
        scene.image.height = ((h * scale).round() as u32).max(1);
        scene.image.min_contribution = 0.0;
        if path_traced {
            let (world, _) = build(&scene, AccelKind::BvhWide)?;
            let rows = sampling_rows(
                &name,
                &scene,
                &world,
                options.reference_samples,
                &options.noise_thresholds,
                &pool,
                progress,
            )?;
            out.sampling.extend(rows);
            continue;
        }
        let (world, _) = build(&scene, AccelKind::BvhWide)?;
        let render_with = |scene: &Scene,
                           adaptive: Option<AdaptiveSupersampling>|
         -> Result<(englobe_render::RenderOutput, f64), LabError> {
            let start = Instant::now();
            let r = Renderer::new(scene, &world).count_work(true);
            let r = match adaptive {
                Some(a) => r.supersampling(a),
                None => r,
            };
            let out = pool.install(|| r.render())?;
            Ok((out, start.elapsed().as_secs_f64()))
        };
        let render = |scene: &Scene| render_with(scene, None);
        progress(format!("{name}: full depth ({})", scene.image.max_depth));
        let (reference, seconds) = render(&scene)?;
        let row = |method: &str, setting: String, stats: &RenderStats, seconds: f64, error: ImageError| FewerRaysRow {
            scene: name.clone(),
            method: method.to_owned(),
            setting,
            rays: [RayKind::Primary, RayKind::Shadow, RayKind::Reflected, RayKind::Refracted]
                .map(|k| stats.kind(k).rays),
            exact_tests: stats.total().exact_tests,
            seconds,
            error,
        };
        let exact = image_error(&reference.film, &reference.film);
        out.rows.push(row("full depth", format!("depth {}", scene.image.max_depth), &reference.stats, seconds, exact));
        for &threshold in &options.thresholds {
            progress(format!("{name}: adaptive depth {threshold}"));
            let mut adaptive = scene.clone();
            adaptive.image.min_contribution = threshold;
            let (image, seconds) = render(&adaptive)?;
            let error = image_error(&image.film, &reference.film);
            out.rows.push(row("adaptive depth", format!("{threshold}"), &image.stats, seconds, error));
        }

        let mut uniform = scene.clone();
        uniform.image.samples = REFERENCE_SAMPLES;
        progress(format!("{name}: uniform supersampling, {REFERENCE_SAMPLES} samples"));
        let (reference, seconds) = render(&uniform)?;
        let exact = image_error(&reference.film, &reference.film);
        out.rows.push(row("uniform, reference", format!("{REFERENCE_SAMPLES} spp"), &reference.stats, seconds, exact));
        for samples in UNIFORM_SAMPLES {
            progress(format!("{name}: uniform supersampling, {samples} samples"));
            uniform.image.samples = samples;
            let (image, seconds) = render(&uniform)?;
            let error = image_error(&image.film, &reference.film);
            out.rows.push(row("uniform", format!("{samples} spp"), &image.stats, seconds, error));
        }
        for (contrast, max_level) in ADAPTIVE_SUPERSAMPLING {
            progress(format!("{name}: adaptive supersampling, contrast {contrast}, level {max_level}"));
            let (image, seconds) = render_with(&scene, Some(AdaptiveSupersampling { contrast, max_level }))?;
            let error = image_error(&image.film, &reference.film);
            out.rows.push(row("adaptive ss", format!("{contrast}/{max_level}"), &image.stats, seconds, error));
        }
        if !scene.textures.is_empty() {
            out.cones.extend(cone_rows(&name, &scene, &world, &pool, progress)?);
        }
    }
    Ok(out)
}

impl FewerRays {
    /// The table: one line per render, the rays of each kind, exact tests, time, and the error.
    pub fn table(&self) -> String {
        let mut s = String::new();
        if self.rows.is_empty() {
            return (sampling_table(&self.sampling) + &cone_table(&self.cones)).trim_start().to_owned();
        }
        let _ = writeln!(
            s,
            "{:<24} {:<18} {:>8} {:>10} {:>10} {:>10} {:>10} {:>13} {:>7} {:>6} {:>7}",
            "scene",
            "method",
            "setting",
            "primary",
            "shadow",
            "reflected",
            "refracted",
            "exact tests",
            "s",
            "RMSE",
            "SSIM"
        );
        for r in &self.rows {
            let _ = writeln!(
                s,
                "{:<24} {:<18} {:>8} {:>10} {:>10} {:>10} {:>10} {:>13} {:>7.3} {:>6.2} {:>7.4}",
                r.scene.trim_start_matches("scenes/"),
                r.method,
                r.setting,
                grouped(r.rays[0]),
                grouped(r.rays[1]),
                grouped(r.rays[2]),
                grouped(r.rays[3]),
                grouped(r.exact_tests),
                r.seconds,
                r.error.rmse,
                r.error.ssim
            );
        }
        s += &sampling_table(&self.sampling);
        s += &cone_table(&self.cones);
        s
    }
}
