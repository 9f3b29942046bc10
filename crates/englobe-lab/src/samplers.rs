//! The pixel samplers measured: the mean squared error of the independent sampler and of the
//! Owen-scrambled Sobol sampler (englobe-render's `sampler`, after Burley 2020, "Practical
//! Hash-based Owen Scrambling") at equal samples per pixel, against a high-sample reference of
//! the same scene, with the log-log slope of each error against the samples (Monte Carlo's
//! `1 / spp` is a slope of -1; stratified samples do better where the integrand is smooth).
//!
//! The reference is rendered with independent samples and another seed, so that it is
//! independent of both renders it judges; its own noise adds its variance (`1 / reference_spp`
//! of one sample's) to every error, a floor the table prints: the independent errors are
//! `v (1 / spp + 1 / reference_spp)` for one sample's variance `v`, which they estimate.

use std::path::PathBuf;

use englobe::{AccelKind, World};
use englobe_render::{Film, Renderer};
use englobe_scene::{SamplerKind, Scene, load_scene};

use crate::error::LabError;
use crate::measure::{build, thread_pool};

/// What to measure.
#[derive(Clone, Debug)]
pub struct SamplerOptions {
    /// The scene (path traced).
    pub scene: PathBuf,
    /// The longer side of the image, in pixels.
    pub size: u32,
    /// Samples per pixel of the reference.
    pub reference_spp: u32,
    /// Samples per pixel of the compared renders.
    pub spps: Vec<u32>,
    /// Worker threads (all cores if `None`).
    pub threads: Option<u32>,
}

impl Default for SamplerOptions {
    fn default() -> Self {
        SamplerOptions {
            scene: PathBuf::from("scenes/cornell-box-path.toml"),
            size: 128,
            reference_spp: 4096,
            spps: vec![4, 16, 64, 256],
            threads: None,
        }
    }
}

/// The errors of both samplers at one sample count.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SamplerRow {
    /// Samples per pixel.
    pub spp: u32,
    /// Mean squared error of the independent sampler's linear RGB values.
    pub independent: f64,
    /// Mean squared error of the Sobol sampler's.
    pub sobol: f64,
}

/// The experiment's result.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SamplerExperiment {
    /// The scene, its image size and the reference's samples.
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub reference_spp: u32,
    /// The reference's mean squared value (to read the errors relative to it).
    pub mean_square: f64,
    pub rows: Vec<SamplerRow>,
}

/// Mean squared difference of two films' linear RGB values, over pixels and channels.
pub fn mean_squared_error(image: &Film, reference: &Film) -> f64 {
    let (a, b) = (image.pixels(), reference.pixels());
    assert_eq!(a.len(), b.len(), "images of one size");
    let sum: f64 =
        a.iter().zip(b).flat_map(|(p, q)| (0..3).map(move |c| (f64::from(p[c]) - f64::from(q[c])).powi(2))).sum();
    sum / (3 * a.len()).max(1) as f64
}

/// The least-squares slope of `ln y` against `ln x`.
pub fn log_log_slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (xs, ys): (Vec<f64>, Vec<f64>) = points.iter().map(|&(x, y)| (x.ln(), y.ln())).unzip();
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx).powi(2)).sum();
    sxy / sxx
}

fn render(scene: &Scene, world: &World, sampler: SamplerKind, seed: u64, spp: u32) -> Result<Film, LabError> {
    let mut scene = scene.clone();
    scene.image.sampler = sampler;
    scene.image.seed = seed;
    Ok(Renderer::new(&scene, world).samples(spp).render()?.film)
}

/// Runs the experiment; `progress` gets a line per render.
pub fn run_samplers(options: &SamplerOptions, progress: &mut dyn FnMut(String)) -> Result<SamplerExperiment, LabError> {
    let pool = thread_pool(options.threads)?;
    let mut scene = load_scene(&options.scene)?;
    let (w, h) = (scene.image.width as f64, scene.image.height as f64);
    let scale = options.size as f64 / w.max(h);
    scene.image.width = ((w * scale).round() as u32).max(1);
    scene.image.height = ((h * scale).round() as u32).max(1);
    scene.image.noise_threshold = 0.0;
    let (world, _) = build(&scene, AccelKind::BvhWide)?;
    let render = |sampler, seed, spp| pool.install(|| render(&scene, &world, sampler, seed, spp));
    progress(format!("reference: {} spp", options.reference_spp));
    let reference = render(SamplerKind::Independent, 0x5eed_0f4e, options.reference_spp)?;
    let mean_square = reference.pixels().iter().map(|p| f64::from(p.length_squared()) / 3.0).sum::<f64>()
        / reference.pixels().len().max(1) as f64;
    let mut rows = Vec::new();
    for &spp in &options.spps {
        progress(format!("{spp} spp"));
        let independent = render(SamplerKind::Independent, 0, spp)?;
        let sobol = render(SamplerKind::Sobol, 0, spp)?;
        rows.push(SamplerRow {
            spp,
            independent: mean_squared_error(&independent, &reference),
            sobol: mean_squared_error(&sobol, &reference),
        });
    }
    Ok(SamplerExperiment {
        scene: options.scene.display().to_string(),
        width: scene.image.width,
        height: scene.image.height,
        reference_spp: options.reference_spp,
        mean_square,
        rows,
    })
}

impl SamplerExperiment {
    /// The slopes of both errors against the samples (independent, Sobol).
    pub fn slopes(&self) -> (f64, f64) {
        let points = |f: fn(&SamplerRow) -> f64| self.rows.iter().map(|r| (r.spp as f64, f(r))).collect::<Vec<_>>();
        (log_log_slope(&points(|r| r.independent)), log_log_slope(&points(|r| r.sobol)))
    }

    /// The reference's own noise in every error: `v / reference_spp`, with one sample's variance
    /// `v` estimated from the independent rows as the mean of `MSE / (1 / spp + 1 / reference_spp)`.
    pub fn reference_floor(&self) -> f64 {
        let r = f64::from(self.reference_spp);
        let v = self.rows.iter().map(|row| row.independent / (1.0 / f64::from(row.spp) + 1.0 / r)).sum::<f64>()
            / self.rows.len().max(1) as f64;
        v / r
    }

    /// The table: one row per sample count, then the slopes and the reference's floor.
    pub fn table(&self) -> String {
        let mut s = format!(
            "{} at {}x{}, reference {} spp (independent, another seed); MSE of linear RGB (relative: / mean square {:.4e})\n",
            self.scene, self.width, self.height, self.reference_spp, self.mean_square
        );
        s += &format!("{:>6} {:>14} {:>14} {:>16}\n", "spp", "independent", "sobol", "sobol/independent");
        for r in &self.rows {
            s += &format!(
                "{:>6} {:>14.4e} {:>14.4e} {:>16.3}\n",
                r.spp,
                r.independent,
                r.sobol,
                r.sobol / r.independent
            );
        }
        let (i, o) = self.slopes();
        s += &format!("log-log slope of MSE against spp: independent {i:.3}, sobol {o:.3}\n");
        s += &format!("the reference's own noise in every MSE: about {:.2e}\n", self.reference_floor());
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_floor_is_the_reference_share_of_independent_errors() {
        // v = 0.5, reference 1000 spp: independent errors 0.5 (1/n + 1/1000), floor 5e-4.
        let rows = [10u32, 100].map(|spp| SamplerRow { spp, independent: 0.5 * (1.0 / spp as f64 + 1e-3), sobol: 0.0 });
        let e = SamplerExperiment {
            scene: String::new(),
            width: 1,
            height: 1,
            reference_spp: 1000,
            mean_square: 1.0,
            rows: rows.to_vec(),
        };
        assert!((e.reference_floor() - 5e-4).abs() < 1e-12);
    }

    #[test]
    fn the_slope_of_a_power_law_is_its_exponent() {
        let points: Vec<(f64, f64)> = [4.0, 16.0, 64.0].iter().map(|&x: &f64| (x, 3.0 * x.powf(-1.25))).collect();
        assert!((log_log_slope(&points) + 1.25).abs() < 1e-12);
    }
}
