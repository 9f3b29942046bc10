//! Generalised rays, measured: ray cones for texture filtering (englobe-render's `ray_cone`,
//! after Amanatides 1984 and Akenine-Möller et al. 2019) against point-sampled textures, on
//! the textured scenes of `englobe experiment fewer-rays`.
//!
//! A far texture aliases when each sample reads it at one point; uniform supersampling averages
//! the aliasing away with more primary rays, a cone reads the average at once. Both are judged
//! against a converged reference: [`REFERENCE_SAMPLES`] jittered samples per pixel without cones,
//! with another seed than the renders it judges (so that its samples are not theirs, as in
//! [`crate::fewer_samples`]). The question is asked the seed's way: how many primary rays does
//! uniform sampling need to reach the error a cone render reaches? It is read off the uniform
//! renders' curve of RMSE against samples per pixel, interpolated in log-log space
//! ([`crate::fewer_samples::uniform_samples_at`]), and divided by the cone render's samples.

use std::fmt::Write as _;
use std::time::Instant;

use englobe::World;
use englobe_render::{RayKind, Renderer};
use englobe_scene::{Scene, TextureFilter};

use crate::error::LabError;
use crate::fewer_samples::uniform_samples_at;
use crate::image_error::{ImageError, image_error};
use crate::report::grouped;

/// Samples per pixel of the reference.
pub const REFERENCE_SAMPLES: u32 = 256;

/// Samples per pixel of the renders without cones.
pub const UNIFORM_SAMPLES: [u32; 4] = [1, 4, 16, 64];

/// Samples per pixel of the renders with cones.
pub const CONE_SAMPLES: [u32; 3] = [1, 4, 16];

/// One render of the comparison.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ConeRow {
    /// The scene file.
    pub scene: String,
    /// The texture filter: `none, reference`, `none` or `cone`.
    pub filter: String,
    /// Samples per pixel.
    pub samples: u32,
    /// Primary rays cast.
    pub primary: u64,
    /// Rays cast, all kinds.
    pub rays: u64,
    /// Exact tests, all kinds.
    pub exact_tests: u64,
    /// Seconds spent rendering (counting on).
    pub seconds: f64,
    /// Against the reference.
    pub error: ImageError,
    /// Cone rows: the samples per pixel uniform sampling without cones needs for the same RMSE
    /// (`None` outside the uniform renders' range).
    pub uniform_equivalent: Option<f64>,
    /// Cone rows: `uniform_equivalent` over `samples`, how many times fewer primary rays the
    /// cones need for their error.
    pub ratio: Option<f64>,
}

/// Renders `scene` (whose world is `world`) without cones at [`UNIFORM_SAMPLES`] and with cones
/// at [`CONE_SAMPLES`], all against the reference; `progress` gets a line per render.
pub fn cone_rows(
    name: &str,
    scene: &Scene,
    world: &World,
    pool: &rayon::ThreadPool,
    progress: &mut dyn FnMut(String),
) -> Result<Vec<ConeRow>, LabError> {
    let render = |filter: TextureFilter, samples: u32, seed: u64| -> Result<_, LabError> {
        let mut s = scene.clone();
        (s.image.texture_filter, s.image.samples, s.image.seed) = (filter, samples, seed);
        let start = Instant::now();
        let out = pool.install(|| Renderer::new(&s, world).count_work(true).render())?;
        Ok((out, start.elapsed().as_secs_f64()))
    };
    let row = |filter: &str, samples: u32, out: &englobe_render::RenderOutput, seconds: f64, error| ConeRow {
        scene: name.to_owned(),
        filter: filter.to_owned(),
        samples,
        primary: out.stats.kind(RayKind::Primary).rays,
        rays: out.stats.total().rays,
        exact_tests: out.stats.total().exact_tests,
        seconds,
        error,
        uniform_equivalent: None,
        ratio: None,
    };
    let seed = scene.image.seed;
    progress(format!("{name}: texture filter none, {REFERENCE_SAMPLES} samples (reference)"));
    let (reference, seconds) = render(TextureFilter::None, REFERENCE_SAMPLES, seed ^ 0x005e_ed0f_c0e5)?;
    let mut rows = vec![row(
        "none, reference",
        REFERENCE_SAMPLES,
        &reference,
        seconds,
        image_error(&reference.film, &reference.film),
    )];
    let mut curve = Vec::new();
    for samples in UNIFORM_SAMPLES {
        progress(format!("{name}: texture filter none, {samples} samples"));
        let (out, seconds) = render(TextureFilter::None, samples, seed)?;
        let error = image_error(&out.film, &reference.film);
        curve.push((samples, error.rmse));
        rows.push(row("none", samples, &out, seconds, error));
    }
    for samples in CONE_SAMPLES {
        progress(format!("{name}: texture filter cone, {samples} samples"));
        let (out, seconds) = render(TextureFilter::Cone, samples, seed)?;
        let error = image_error(&out.film, &reference.film);
        let mut r = row("cone", samples, &out, seconds, error);
        r.uniform_equivalent = uniform_samples_at(error.rmse, &curve);
        r.ratio = r.uniform_equivalent.map(|n| n / samples as f64);
        rows.push(r);
    }
    Ok(rows)
}

/// The table of [`cone_rows`]' rows (empty without rows).
pub fn cone_table(rows: &[ConeRow]) -> String {
    let mut s = String::new();
    if rows.is_empty() {
        return s;
    }
    let _ = writeln!(
        s,
        "\n{:<24} {:<16} {:>5} {:>10} {:>11} {:>13} {:>7} {:>6} {:>7} {:>12} {:>7}",
        "scene", "texture filter", "spp", "primary", "rays", "exact tests", "s", "RMSE", "SSIM", "uniform spp", "fewer"
    );
    for r in rows {
        let (equivalent, ratio) = match (r.filter.as_str(), r.uniform_equivalent, r.ratio) {
            (_, Some(n), Some(x)) => (format!("{n:.1}"), format!("{x:.2}x")),
            ("cone", _, _) => ("out of range".to_owned(), "-".to_owned()),
            _ => (String::new(), String::new()),
        };
        let line = format!(
            "{:<24} {:<16} {:>5} {:>10} {:>11} {:>13} {:>7.3} {:>6.2} {:>7.4} {:>12} {:>7}",
            r.scene.trim_start_matches("scenes/"),
            r.filter,
            r.samples,
            grouped(r.primary),
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
    fn cones_cast_the_same_rays_for_less_error_on_the_textured_ground() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/textured-ground.toml");
        let mut scene = englobe_scene::load_scene(&path).unwrap();
        (scene.image.width, scene.image.height) = (64, 36);
        let (world, _) = build(&scene, AccelKind::BvhWide).unwrap();
        let pool = thread_pool(Some(2)).unwrap();
        let rows = cone_rows("ground", &scene, &world, &pool, &mut |_| {}).unwrap();
        assert_eq!(rows.len(), 1 + UNIFORM_SAMPLES.len() + CONE_SAMPLES.len());
        let find =
            |filter: &str, samples: u32| rows.iter().find(|r| r.filter == filter && r.samples == samples).unwrap();
        for samples in CONE_SAMPLES {
            let (cone, none) = (find("cone", samples), find("none", samples));
            // The cone changes what a ray reads, not which rays are cast.
            assert_eq!((cone.primary, cone.rays, cone.exact_tests), (none.primary, none.rays, none.exact_tests));
            assert_eq!(cone.primary, 64 * 36 * samples as u64);
            assert!(
                cone.error.rmse < none.error.rmse,
                "{samples} spp: {} against {}",
                cone.error.rmse,
                none.error.rmse
            );
        }
        // One sample per pixel with cones is worth more than one without: the ratio says how much.
        let one = find("cone", 1);
        assert!(one.ratio.is_none_or(|r| r > 1.0), "{:?}", one.ratio);
        assert!(cone_table(&rows).contains("fewer"));
    }
}
