//! Adaptive sampling against what it must equal: every pixel is bit for bit the pixel of a
//! uniform render with as many samples as it took; the image does not depend on the threads nor
//! on the window rendered; flat areas stop at the first pass; a time limit keeps whole passes.

use std::collections::BTreeSet;
use std::time::{Duration, Instant};

use englobe::AccelKind;
use englobe_render::adaptive::BLOCK_SIZE;
use englobe_render::supersample::AdaptiveSupersampling;
use englobe_render::{DEFAULT_SCENE, Film, PixelWindow, RayKind, RenderOutput, Renderer, build_world};
use englobe_scene::{IntegratorKind, NoiseAllocation, Scene, parse_scene};

/// The default scene path traced, small: sky (flat) around noisy diffuse spheres.
fn scene(threshold: f32) -> Scene {
    let mut s = parse_scene(DEFAULT_SCENE, "default.toml".as_ref()).unwrap();
    s.image.width = 44;
    s.image.height = 30;
    s.image.samples = 48;
    s.image.integrator = IntegratorKind::Path;
    s.image.noise_threshold = threshold;
    s.image.min_samples = Some(8);
    s
}

fn render_on(s: &Scene, threads: usize, window: Option<PixelWindow>) -> RenderOutput {
    let world = build_world(s, AccelKind::BvhWide).unwrap();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| {
        let r = Renderer::new(s, &world);
        match window {
            Some(w) => r.window(w).render().unwrap(),
            None => r.render().unwrap(),
        }
    })
}

fn bits(f: &Film) -> Vec<[u32; 3]> {
    f.pixels().iter().map(|p| p.to_array().map(f32::to_bits)).collect()
}

#[test]
fn every_pixel_is_the_uniform_render_of_its_own_sample_count() {
    let s = scene(0.05);
    let out = render_on(&s, 2, None);
    assert!(out.complete);
    let map = out.samples_map.as_ref().expect("adaptive renders say each pixel's samples");
    let counts: BTreeSet<u64> = map.values().iter().copied().collect();
    assert!(counts.len() >= 2, "some blocks stop before others: {counts:?}");
    assert_eq!(*counts.first().unwrap(), 8, "the first pass");
    assert!(counts.iter().all(|&n| [8, 10, 13, 17, 22, 28, 35, 44, 48].contains(&n)), "the schedule: {counts:?}");
    assert_eq!(out.samples_done as u64, *counts.last().unwrap());
    // Samples are primary rays, one each.
    assert_eq!(out.stats.kind(RayKind::Primary).rays, map.total());
    for &n in &counts {
        let mut uniform = s.clone();
        uniform.image.noise_threshold = 0.0;
        uniform.image.samples = n as u32;
        let reference = render_on(&uniform, 2, None);
        assert!(reference.samples_map.is_none());
        let mut matched = 0;
        for y in 0..s.image.height {
            for x in 0..s.image.width {
                if map.get(x, y) == n {
                    let (a, b) = (out.film.get(x, y), reference.film.get(x, y));
                    assert_eq!(a.to_array().map(f32::to_bits), b.to_array().map(f32::to_bits), "({x}, {y}) at {n}");
                    matched += 1;
                }
            }
        }
        assert!(matched > 0);
    }
    // A block's pixels stop together.
    for y in 0..s.image.height {
        for x in 0..s.image.width {
            let corner = map.get(x / BLOCK_SIZE * BLOCK_SIZE, y / BLOCK_SIZE * BLOCK_SIZE);
            assert_eq!(map.get(x, y), corner, "({x}, {y})");
        }
    }
}

#[test]
fn the_same_bytes_on_one_thread_or_many() {
    for allocation in [NoiseAllocation::Even, NoiseAllocation::Mse] {
        let mut s = scene(0.03);
        s.image.noise_allocation = allocation;
        let one = render_on(&s, 1, None);
        for threads in [2, 3] {
            let many = render_on(&s, threads, None);
            assert_eq!(bits(&one.film), bits(&many.film), "{allocation:?}, {threads} threads");
            assert_eq!(one.samples_map, many.samples_map);
            assert_eq!(one.stats, many.stats);
        }
    }
}

#[test]
fn the_mse_allocation_takes_fewer_samples_where_noise_is_high() {
    // The same threshold: equal at the first pass, so the sky's blocks stop alike; where noise
    // keeps blocks sampling, mse relaxes the threshold as they go and takes fewer samples.
    let even = render_on(&scene(0.02), 1, None);
    let mut s = scene(0.02);
    s.image.noise_allocation = NoiseAllocation::Mse;
    let mse = render_on(&s, 1, None);
    let (e, m) = (even.samples_map.unwrap(), mse.samples_map.unwrap());
    let (e, m) = (e.values(), m.values());
    assert_eq!(e.len(), m.len());
    assert!(e.iter().zip(m).all(|(a, b)| b <= a), "no block takes more with mse");
    assert!(m.iter().sum::<u64>() < e.iter().sum::<u64>());
    assert_eq!(e.iter().min(), m.iter().min(), "the first pass is the same");
}

#[test]
fn flat_sky_stops_at_the_first_pass_and_noise_takes_more() {
    let s = scene(0.03);
    let out = render_on(&s, 2, None);
    let map = out.samples_map.unwrap();
    // The top-left block sees the sky alone (one colour, no noise); the block at the image's
    // centre sees a diffuse sphere.
    let sky = s.image.background;
    for y in 0..BLOCK_SIZE {
        for x in 0..BLOCK_SIZE {
            assert!((out.film.get(x, y) - sky).abs().max_element() < 1e-6, "({x}, {y}) is sky");
        }
    }
    assert_eq!(map.get(0, 0), 8);
    let (cx, cy) = (s.image.width / 2, s.image.height / 2);
    assert!(map.get(cx, cy) > 8, "{} samples on the sphere", map.get(cx, cy));
    assert!(map.total() < (s.image.width * s.image.height * s.image.samples) as u64);
}

#[test]
fn a_window_holds_the_whole_render_s_pixels() {
    let s = scene(0.03);
    let full = render_on(&s, 2, None);
    let full_map = full.samples_map.as_ref().unwrap();
    // Windows whose edges cut blocks, as the strips of `--tile K/N` do.
    for w in [
        PixelWindow { x0: 0, x1: 44, y0: 5, y1: 13 },
        PixelWindow { x0: 3, x1: 30, y0: 17, y1: 30 },
        PixelWindow { x0: 40, x1: 44, y0: 29, y1: 30 },
    ] {
        let part = render_on(&s, 2, Some(w));
        assert_eq!(part.window, w);
        assert_eq!((part.film.width(), part.film.height()), (w.width(), w.height()));
        let map = part.samples_map.as_ref().unwrap();
        for y in w.y0..w.y1 {
            for x in w.x0..w.x1 {
                let (a, b) = (part.film.get(x - w.x0, y - w.y0), full.film.get(x, y));
                assert_eq!(a.to_array().map(f32::to_bits), b.to_array().map(f32::to_bits), "({x}, {y}) of {w}");
                assert_eq!(map.get(x - w.x0, y - w.y0), full_map.get(x, y));
            }
        }
    }
}

#[test]
fn by_passes_it_is_the_same_render_and_a_deadline_keeps_whole_passes() {
    let s = scene(0.03);
    let world = build_world(&s, AccelKind::BvhWide).unwrap();
    let tiled = Renderer::new(&s, &world).render().unwrap();
    let passes = Renderer::new(&s, &world).render_passes(None).unwrap();
    assert!(passes.complete);
    assert_eq!(bits(&tiled.film), bits(&passes.film));
    // A deadline already passed: no pass is done, nothing is claimed.
    let none = Renderer::new(&s, &world).render_passes(Some(Instant::now() - Duration::from_secs(1))).unwrap();
    assert!(!none.complete);
    assert_eq!(none.samples_done, 0);
    // Progress counts samples per pixel, pass by pass, up to the last.
    let seen = std::sync::Mutex::new(Vec::new());
    let record = |done: usize, total: usize| seen.lock().unwrap().push((done, total));
    Renderer::new(&s, &world).on_progress(&record).render_passes(None).unwrap();
    let seen = seen.into_inner().unwrap();
    assert_eq!(seen.first(), Some(&(8, 48)));
    assert!(seen.windows(2).all(|w| w[0].0 < w[1].0), "{seen:?}");
    assert_eq!(seen.last().unwrap().0, passes.samples_done as usize);
}

#[test]
fn the_cost_aov_sums_each_pixel_s_samples() {
    let s = scene(0.03);
    let world = build_world(&s, AccelKind::BvhWide).unwrap();
    let out = Renderer::new(&s, &world).record_cost(true).render().unwrap();
    let cost = out.cost.unwrap();
    let total = out.stats.total();
    assert_eq!(cost.total(), total.nodes_visited + total.exact_tests);
}

#[test]
fn what_it_cannot_be_combined_with_is_refused() {
    let s = scene(0.03);
    let world = build_world(&s, AccelKind::BvhWide).unwrap();
    let stride = Renderer::new(&s, &world).pixel_stride(2).render().unwrap_err().to_string();
    assert!(stride.contains("noise_threshold"), "{stride}");
    let supersampling = Renderer::new(&s, &world)
        .supersampling(AdaptiveSupersampling { contrast: 0.1, max_level: 2 })
        .render()
        .unwrap_err()
        .to_string();
    assert!(supersampling.contains("cannot be combined"), "{supersampling}");
    // One sample per pixel has no halves to compare: a uniform render.
    let mut one = s.clone();
    one.image.samples = 1;
    assert!(Renderer::new(&one, &world).render().unwrap().samples_map.is_none());
}
