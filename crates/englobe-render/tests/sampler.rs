//! The Sobol pixel sampler keeps the renderer's guarantees: the same bytes on any number of
//! threads, by tiles or by passes, in a window, and adaptively (every pixel the uniform render's
//! of its sample count); and it lowers the error against a high-sample reference at equal
//! samples, where the independent sampler's is `1 / spp`.

use std::collections::BTreeSet;

use englobe::AccelKind;
use englobe_render::{DEFAULT_SCENE, Film, PixelWindow, RenderOutput, Renderer, build_world};
use englobe_scene::{IntegratorKind, SamplerKind, Scene, parse_scene};

/// The default scene path traced, small, with the Sobol sampler.
fn scene(samples: u32) -> Scene {
    let mut s = parse_scene(DEFAULT_SCENE, "default.toml".as_ref()).unwrap();
    s.image.width = 40;
    s.image.height = 28;
    s.image.samples = samples;
    s.image.integrator = IntegratorKind::Path;
    s.image.sampler = SamplerKind::Sobol;
    s
}

fn render_on(s: &Scene, threads: usize, window: Option<PixelWindow>, passes: bool) -> RenderOutput {
    let world = build_world(s, AccelKind::BvhWide).unwrap();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| {
        let mut r = Renderer::new(s, &world);
        if let Some(w) = window {
            r = r.window(w);
        }
        if passes { r.render_passes(None).unwrap() } else { r.render().unwrap() }
    })
}

fn bits(f: &Film) -> Vec<[u32; 3]> {
    f.pixels().iter().map(|p| p.to_array().map(f32::to_bits)).collect()
}

fn mse(a: &Film, b: &Film) -> f64 {
    let sum: f64 = a
        .pixels()
        .iter()
        .zip(b.pixels())
        .flat_map(|(p, q)| (0..3).map(move |c| (f64::from(p[c]) - f64::from(q[c])).powi(2)))
        .sum();
    sum / (3 * a.pixels().len()) as f64
}

#[test]
fn the_same_bytes_on_any_threads_by_tiles_by_passes_and_in_a_window() {
    let s = scene(12);
    let one = render_on(&s, 1, None, false);
    let mut independent = s.clone();
    independent.image.sampler = SamplerKind::Independent;
    assert_ne!(bits(&one.film), bits(&render_on(&independent, 1, None, false).film), "the sampler is used");
    for threads in [2, 3] {
        assert_eq!(bits(&one.film), bits(&render_on(&s, threads, None, false).film), "{threads} threads");
    }
    assert_eq!(bits(&one.film), bits(&render_on(&s, 2, None, true).film), "by passes");
    let w = PixelWindow { x0: 7, x1: 31, y0: 3, y1: 20 };
    let part = render_on(&s, 2, Some(w), false);
    for y in w.y0..w.y1 {
        for x in w.x0..w.x1 {
            let (a, b) = (part.film.get(x - w.x0, y - w.y0), one.film.get(x, y));
            assert_eq!(a.to_array().map(f32::to_bits), b.to_array().map(f32::to_bits), "({x}, {y})");
        }
    }
}

#[test]
fn adaptively_every_pixel_is_the_uniform_render_of_its_sample_count() {
    let mut s = scene(32);
    s.image.noise_threshold = 0.05;
    s.image.min_samples = Some(8);
    let out = render_on(&s, 2, None, false);
    assert_eq!(bits(&out.film), bits(&render_on(&s, 3, None, false).film));
    let map = out.samples_map.as_ref().expect("adaptive renders say each pixel's samples");
    let counts: BTreeSet<u64> = map.values().iter().copied().collect();
    assert!(counts.len() >= 2, "some blocks stop before others: {counts:?}");
    for &n in &counts {
        let mut uniform = s.clone();
        uniform.image.noise_threshold = 0.0;
        uniform.image.samples = n as u32;
        let reference = render_on(&uniform, 2, None, false);
        for y in 0..s.image.height {
            for x in 0..s.image.width {
                if map.get(x, y) == n {
                    let (a, b) = (out.film.get(x, y), reference.film.get(x, y));
                    assert_eq!(a.to_array().map(f32::to_bits), b.to_array().map(f32::to_bits), "({x}, {y}) at {n}");
                }
            }
        }
    }
}

#[test]
fn sobol_samples_lower_the_error_at_equal_samples() {
    // Against a 512-spp independent reference of another seed, at 16 spp. The numbers are fixed
    // by the seeds, so the comparison is deterministic; `englobe experiment samplers` measures it
    // at more sample counts on the Cornell box.
    let mut reference = scene(512);
    reference.image.sampler = SamplerKind::Independent;
    reference.image.seed = 99;
    let reference = render_on(&reference, 2, None, false).film;
    let sobol = render_on(&scene(16), 2, None, false).film;
    let mut independent = scene(16);
    independent.image.sampler = SamplerKind::Independent;
    let independent = render_on(&independent, 2, None, false).film;
    let (e_sobol, e_independent) = (mse(&sobol, &reference), mse(&independent, &reference));
    assert!(e_sobol < 0.8 * e_independent, "Sobol {e_sobol:.3e}, independent {e_independent:.3e}");
    // And it converges to the same image: its mean is the reference's within 1%.
    let mean = |f: &Film| f.pixels().iter().map(|p| f64::from(p.element_sum())).sum::<f64>();
    let ratio = mean(&sobol) / mean(&reference);
    assert!((ratio - 1.0).abs() < 0.01, "{ratio}");
}
