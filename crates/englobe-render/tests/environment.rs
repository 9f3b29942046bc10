//! The environment light: the shared maps load, sampling finds the sunset's sun, samples follow
//! their density (a chi-square test over the sphere), and the path tracer's estimate under an
//! environment matches closed forms and pure BSDF sampling.

#[path = "common/chi2.rs"]
mod chi2;

use std::f64::consts::PI;
use std::path::PathBuf;
use std::sync::Arc;

use englobe::{AccelKind, Vec2, Vec3};
use englobe_render::environment::{EnvironmentLight, luminance};
use englobe_render::sampling::cosine_hemisphere;
use englobe_render::{Renderer, build_world};
use englobe_scene::environment::load_environment_map;
use englobe_scene::shared_data::locate_shared;
use englobe_scene::{Environment, EnvironmentMap, Scene, Sky, parse_scene};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg32;

fn shared_env(name: &str) -> PathBuf {
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let shared =
        locate_shared(&here).unwrap_or_else(|| panic!("the shared scene data was not found above {}", here.display()));
    shared.join("scenes").join("env").join(name)
}

fn map_environment(map: EnvironmentMap, rotation_degrees: f32) -> Environment {
    Environment { sky: Sky::Map(Arc::new(map)), intensity: 1.0, rotation_degrees }
}

/// A 64 x 32 map: a sky brighter towards the top, a darker ground, and a small hot "sun".
fn synthetic_map() -> EnvironmentMap {
    let (w, h) = (64u32, 32u32);
    let mut pixels = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let up = 1.0 - y as f32 / h as f32;
            let mut p = if y < h / 2 { Vec3::new(0.3, 0.5, 1.0) * (0.5 + up) } else { Vec3::new(0.2, 0.15, 0.1) };
            if (40..42).contains(&x) && (9..11).contains(&y) {
                p = Vec3::new(400.0, 380.0, 300.0);
            }
            if x % 7 == 3 {
                p *= 0.2; // stripes, so that columns differ
            }
            pixels.push(p);
        }
    }
    EnvironmentMap { path: "synthetic.exr".into(), width: w, height: h, pixels }
}

#[test]
fn the_four_shared_maps_load() {
    for name in ["courtyard.exr", "forest.exr", "studio.exr", "sunset.exr"] {
        let map = load_environment_map(&shared_env(name)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!((map.width, map.height), (1024, 512), "{name}");
        assert!(map.pixels.iter().all(|p| p.is_finite() && p.min_element() >= 0.0), "{name}");
        let light = EnvironmentLight::new(&map_environment(map, 0.0));
        assert!(!light.is_black(), "{name}");
    }
}

#[test]
fn sampling_finds_the_sun_of_the_sunset() {
    let map = load_environment_map(&shared_env("sunset.exr")).unwrap();
    let (w, h) = (map.width as usize, map.height as usize);
    let sin_row = |y: usize| (std::f32::consts::PI * (y as f32 + 0.5) / h as f32).sin();
    // The brightest pixel, and the share of the sampling weight (luminance times sin θ) of the
    // 9 x 9 pixels around it.
    let (sun, peak) = map
        .pixels
        .iter()
        .enumerate()
        .map(|(i, p)| (i, luminance(*p)))
        .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
    let (sx, sy) = (sun % w, sun / w);
    eprintln!("sun at pixel ({sx}, {sy}), luminance {peak}");
    assert!(peak > 1000.0, "the sunset's sun is very bright: {peak}");
    let near = |x: usize, y: usize| x.abs_diff(sx) <= 4 && y.abs_diff(sy) <= 4;
    let (mut total, mut around) = (0.0f64, 0.0f64);
    for y in 0..h {
        for x in 0..w {
            let weight = (luminance(map.get(x as u32, y as u32)) * sin_row(y)) as f64;
            total += weight;
            if near(x, y) {
                around += weight;
            }
        }
    }
    let share = around / total;
    let light = EnvironmentLight::new(&map_environment(map, 0.0));
    let mut rng = Pcg32::seed_from_u64(7);
    let n = 200_000;
    let mut hits = 0usize;
    let mut counts = vec![0u32; w * h];
    for _ in 0..n {
        let s = light.sample(Vec2::new(rng.random(), rng.random())).unwrap();
        let uv = light.uv(s.direction);
        let (x, y) = (((uv.x * w as f32) as usize).min(w - 1), ((uv.y * h as f32) as usize).min(h - 1));
        counts[y * w + x] += 1;
        if near(x, y) {
            hits += 1;
        }
    }
    let got = hits as f64 / n as f64;
    let sigma = (share * (1.0 - share) / n as f64).sqrt();
    eprintln!("samples near the sun: {got:.4}, expected {share:.4} (sigma {sigma:.5})");
    // 81 of the map's half a million pixels hold a fortieth of its light.
    assert!(share > 100.0 * 81.0 / (w * h) as f64, "the sun stands out: {share}");
    assert!((got - share).abs() < 5.0 * sigma, "{got} against {share}");
    // The pixel sampled most often is the sun's neighbourhood.
    let most = counts.iter().enumerate().max_by_key(|(_, c)| **c).unwrap().0;
    assert!(near(most % w, most / w), "most samples at pixel ({}, {})", most % w, most / w);
}

/// Counts of `n` samples of `light` in a grid of `rows` (θ) by `columns` (φ) bins over the sphere,
/// against the counts the density predicts (its integral over each bin, by the midpoint rule on
/// `sub` x `sub` cells of each bin in (θ, φ)).
fn chi2_of(light: &EnvironmentLight, n: usize, rows: usize, columns: usize, sub: usize, seed: u64) -> f64 {
    let bin_of = |d: Vec3| {
        let theta = (d.y as f64).clamp(-1.0, 1.0).acos();
        let phi = (d.z as f64).atan2(d.x as f64).rem_euclid(2.0 * PI);
        let r = ((theta / PI * rows as f64) as usize).min(rows - 1);
        let c = ((phi / (2.0 * PI) * columns as f64) as usize).min(columns - 1);
        r * columns + c
    };
    let mut observed = vec![0.0; rows * columns];
    let mut rng = Pcg32::seed_from_u64(seed);
    for _ in 0..n {
        if let Some(s) = light.sample(Vec2::new(rng.random(), rng.random())) {
            observed[bin_of(s.direction)] += 1.0;
        }
    }
    let (dt, dp) = (PI / (rows * sub) as f64, 2.0 * PI / (columns * sub) as f64);
    let mut expected = vec![0.0; rows * columns];
    let mut total = 0.0;
    for i in 0..rows * sub {
        let theta = (i as f64 + 0.5) * dt;
        let (sin_t, cos_t) = theta.sin_cos();
        for j in 0..columns * sub {
            let phi = (j as f64 + 0.5) * dp;
            let d = Vec3::new((sin_t * phi.cos()) as f32, cos_t as f32, (sin_t * phi.sin()) as f32);
            let mass = light.pdf(d) as f64 * sin_t * dt * dp;
            expected[(i / sub) * columns + j / sub] += mass * n as f64;
            total += mass;
        }
    }
    assert!((total - 1.0).abs() < 1e-3, "the density integrates to {total}");
    let (p, statistic, dof) = chi2::chi2_test(&observed, &expected);
    eprintln!("chi-square {statistic:.1} for {dof} degrees of freedom: p = {p:.4}");
    p
}

#[test]
fn samples_follow_the_density_by_a_chi_square_test() {
    // Bins whose edges fall on the pixels' (the map's 64 x 32 pixels, turned by a quarter, in
    // 16 x 32 bins; the sunset's 1024 x 512 in 32 x 64): the midpoint rule integrates the density
    // exactly there, since density times sin θ is constant over a pixel.
    let synthetic = EnvironmentLight::new(&map_environment(synthetic_map(), 90.0));
    assert!(chi2_of(&synthetic, 1_000_000, 16, 32, 4, 1) > 0.01);
    let sunset = EnvironmentLight::new(&map_environment(load_environment_map(&shared_env("sunset.exr")).unwrap(), 0.0));
    assert!(chi2_of(&sunset, 1_000_000, 32, 64, 16, 2) > 0.01);
    // The sky gradient, sampled through its table of rows.
    let sky = Environment {
        sky: Sky::Gradient { zenith: Vec3::new(0.1, 0.3, 1.0), horizon: Vec3::ONE, ground: Vec3::splat(0.05) },
        intensity: 1.0,
        rotation_degrees: 0.0,
    };
    assert!(chi2_of(&EnvironmentLight::new(&sky), 1_000_000, 16, 8, 4, 3) > 0.01);
}

#[test]
fn a_density_that_lies_is_caught() {
    // The same test must reject a wrong density: here, samples of one map against the density of
    // the same map turned by a pixel.
    let honest = EnvironmentLight::new(&map_environment(synthetic_map(), 0.0));
    let turned = EnvironmentLight::new(&map_environment(synthetic_map(), 360.0 / 64.0));
    let mut observed = vec![0.0; 16 * 32];
    let mut rng = Pcg32::seed_from_u64(9);
    let n = 200_000;
    let bin = |d: Vec3| {
        let uv = englobe_render::environment::direction_to_uv(d);
        ((uv.y * 16.0) as usize).min(15) * 32 + ((uv.x * 32.0) as usize).min(31)
    };
    for _ in 0..n {
        observed[bin(honest.sample(Vec2::new(rng.random(), rng.random())).unwrap().direction)] += 1.0;
    }
    let mut expected = vec![0.0; 16 * 32];
    for _ in 0..n {
        expected[bin(turned.sample(Vec2::new(rng.random(), rng.random())).unwrap().direction)] += 1.0;
    }
    // Expected counts from a second sampler's histogram are noisy themselves; the shift alone
    // still gives p far below 0.01.
    let (p, ..) = chi2::chi2_test(&observed, &expected);
    assert!(p < 1e-6, "p = {p}");
}

fn scene(text: &str) -> Scene {
    parse_scene(text, "test.toml".as_ref()).unwrap_or_else(|e| panic!("{e}"))
}

/// The pixels of `scene` rendered by the path tracer.
fn render(scene: &Scene) -> Vec<Vec3> {
    let world = build_world(scene, AccelKind::BvhWide).unwrap();
    Renderer::new(scene, &world).render().unwrap().film.pixels().to_vec()
}

/// Mean and standard error of the mean of `values`.
fn mean_and_error(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

#[test]
fn a_diffuse_sphere_under_a_constant_environment_is_its_albedo() {
    // Under a constant environment of radiance 1 every point of a convex diffuse object reflects
    // rho: the path tracer's estimate (environment sampling and bounces, weighted by the power
    // heuristic) must find it within its error bars.
    let s = scene(
        r#"
[image]
width = 32
height = 32
samples = 4
max_depth = 4
integrator = "path"
[camera]
position = [0, 0, -4]
look_at = [0, 0, 0]
fov = 40
[environment]
color = [1, 1, 1]
[materials.m]
diffuse = [0.6, 0.3, 0.9]
[[sphere]]
center = [0, 0, 0]
radius = 1
material = "m"
"#,
    );
    let pixels = render(&s);
    // The pixels well inside the silhouette (a radius of 11.3 pixels).
    let inside: Vec<Vec3> = pixels
        .iter()
        .enumerate()
        .filter(|(i, _)| {
            let (x, y) = ((i % 32) as f32 - 15.5, (i / 32) as f32 - 15.5);
            (x * x + y * y).sqrt() < 8.0
        })
        .map(|(_, p)| *p)
        .collect();
    assert!(inside.len() > 100);
    for (channel, rho) in [0.6, 0.3, 0.9].into_iter().enumerate() {
        let values: Vec<f64> = inside.iter().map(|p| p[channel] as f64).collect();
        let (mean, error) = mean_and_error(&values);
        eprintln!("channel {channel}: {mean:.4} +- {error:.4}, expected {rho}");
        assert!(error > 0.0 && error < 0.02, "{error}");
        assert!((mean - rho).abs() < 4.0 * error, "channel {channel}: {mean} +- {error} against {rho}");
    }
    // Rays that miss the sphere see the environment itself.
    assert_eq!(pixels[0], Vec3::ONE);
}

/// A diffuse plane through the origin, of unit normal `n` and albedo 0.5, seen from its front
/// (every pixel sees it), under `env`: each pixel's expected value is the same, `rho / π` times
/// the irradiance.
fn plane_under(n: Vec3, env_table: &str, samples: u32) -> Scene {
    let eye = n * 5.0;
    let up = if n.y.abs() > 0.9 { "[0, 0, 1]" } else { "[0, 1, 0]" };
    scene(&format!(
        r#"
[image]
width = 24
height = 24
samples = {samples}
max_depth = 1
integrator = "path"
[camera]
position = [{}, {}, {}]
look_at = [0, 0, 0]
up = {up}
fov = 30
[materials.m]
diffuse = [0.5, 0.5, 0.5]
[[plane]]
point = [0, 0, 0]
normal = [{}, {}, {}]
material = "m"
{env_table}
"#,
        eye.x, eye.y, eye.z, n.x, n.y, n.z
    ))
}

/// `rho / π` times the irradiance that `light` gives a surface of unit normal `n`, by the
/// midpoint rule on the map's pixels, each cut in `sub` x `sub` (neither the bilinear radiance
/// nor the cosine is constant over a pixel).
fn reflected_exactly(light: &EnvironmentLight, width: usize, height: usize, rho: f64, n: Vec3) -> f64 {
    let sub = 8;
    let (dt, dp) = (PI / (height * sub) as f64, 2.0 * PI / (width * sub) as f64);
    let mut irradiance = 0.0;
    for i in 0..height * sub {
        let theta = (i as f64 + 0.5) * dt;
        let v = (theta / PI) as f32;
        for j in 0..width * sub {
            let u = (j as f64 + 0.5) / (width * sub) as f64;
            let d = light.direction(Vec2::new(u as f32, v));
            let cos = d.dot(n) as f64;
            if cos > 0.0 {
                irradiance += light.radiance(d).x as f64 * cos * theta.sin() * dt * dp;
            }
        }
    }
    rho / PI * irradiance
}

/// Pure BSDF sampling of a plane of normal `normal`: cosine-weighted directions, each bringing
/// `rho L`.
fn bsdf_only(light: &EnvironmentLight, n: usize, rho: f64, normal: Vec3, seed: u64) -> Vec<f64> {
    let mut rng = Pcg32::seed_from_u64(seed);
    (0..n).map(|_| rho * light.radiance(cosine_hemisphere(normal, rng.random(), rng.random())).x as f64).collect()
}

#[test]
fn multiple_importance_sampling_agrees_with_pure_bsdf_sampling_and_the_exact_integral() {
    let dir = tempfile::tempdir().unwrap();
    let map = synthetic_map();
    let light = EnvironmentLight::new(&map_environment(map.clone(), 30.0));
    let exact = reflected_exactly(&light, 64, 32, 0.5, Vec3::Y);
    // The scene reads the same map from a file.
    let path = dir.path().join("synthetic.exr");
    write_map(&map, &path);
    let s = plane_under(Vec3::Y, &format!("[environment]\nfile = \"{}\"\nrotation = 30\n", path.display()), 16);
    let mis: Vec<f64> = render(&s).iter().map(|p| p.x as f64).collect();
    let (mis_mean, mis_error) = mean_and_error(&mis);
    let (bsdf_mean, bsdf_error) = mean_and_error(&bsdf_only(&light, 1_000_000, 0.5, Vec3::Y, 11));
    eprintln!("exact {exact:.5}, MIS {mis_mean:.5} +- {mis_error:.5}, BSDF only {bsdf_mean:.5} +- {bsdf_error:.5}");
    let both = (mis_error * mis_error + bsdf_error * bsdf_error).sqrt();
    assert!((mis_mean - bsdf_mean).abs() < 4.0 * both, "MIS {mis_mean} against BSDF sampling {bsdf_mean}");
    assert!((mis_mean - exact).abs() < 4.0 * mis_error, "MIS {mis_mean} against {exact}");
    assert!((bsdf_mean - exact).abs() < 4.0 * bsdf_error, "BSDF sampling {bsdf_mean} against {exact}");
}

#[test]
fn the_sunset_renders_without_fireflies() {
    // The sun is a few pixels of radiance in the thousands: a bounce finds it rarely and then
    // brings a firefly; sampling the environment finds it every time. A plane facing the sun, its
    // path-traced 4-sample pixels against pixels of 4 cosine-weighted samples.
    let env = format!("[environment]\nfile = \"{}\"\n", shared_env("sunset.exr").display());
    let probe = plane_under(Vec3::Y, &env, 1);
    let light = EnvironmentLight::new(probe.environment.as_ref().unwrap());
    let Sky::Map(map) = &probe.environment.as_ref().unwrap().sky else { unreachable!() };
    let sun = map.pixels.iter().enumerate().max_by(|a, b| luminance(*a.1).total_cmp(&luminance(*b.1))).unwrap().0;
    let (w, h) = (map.width as usize, map.height as usize);
    let sun_dir = light.direction(Vec2::new(((sun % w) as f32 + 0.5) / w as f32, ((sun / w) as f32 + 0.5) / h as f32));
    let s = plane_under(sun_dir, &env, 4);
    let mis: Vec<f64> = render(&s).iter().map(|p| p.x as f64).collect();
    let bsdf = bsdf_only(&light, 200_000, 0.5, sun_dir, 5);
    let exact = reflected_exactly(&light, w, h, 0.5, sun_dir);
    let (mis_mean, mis_error) = mean_and_error(&mis);
    let (bsdf_mean, bsdf_error) = mean_and_error(&bsdf);
    let brightest = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
    let (mis_max, bsdf_max) = (brightest(&mis), brightest(&bsdf));
    // Standard deviations of one sample: the pixels hold 4.
    let (mis_sd, bsdf_sd) = (mis_error * (mis.len() as f64 * 4.0).sqrt(), bsdf_error * (bsdf.len() as f64).sqrt());
    eprintln!(
        "sun towards {sun_dir}; exact {exact:.4}; MIS {mis_mean:.4} +- {mis_error:.4} (one sample's sd {mis_sd:.3}), \
         brightest pixel {mis_max:.4}; BSDF only {bsdf_mean:.4} +- {bsdf_error:.4} (sd {bsdf_sd:.3}), \
         brightest sample {bsdf_max:.1}"
    );
    assert!((mis_mean - exact).abs() < 4.0 * mis_error, "MIS {mis_mean} against {exact}");
    assert!((bsdf_mean - exact).abs() < 4.0 * bsdf_error, "BSDF sampling {bsdf_mean} against {exact}");
    assert!(bsdf_max > 1000.0 * exact, "a bounce that finds the sun brings a firefly: {bsdf_max}");
    assert!(mis_max < 6.0 * exact, "a firefly: {mis_max} where {exact} is expected");
    assert!(mis_sd < 0.25 * bsdf_sd, "one sample's spread: MIS {mis_sd} against BSDF sampling {bsdf_sd}");
}

/// Writes `map` as a 32-bit float OpenEXR file.
fn write_map(map: &EnvironmentMap, path: &std::path::Path) {
    let mut film = englobe_render::Film::new(map.width, map.height);
    for y in 0..map.height {
        for x in 0..map.width {
            film.set(x, y, map.get(x, y));
        }
    }
    englobe_render::write_image(&film, path).unwrap();
}

#[test]
fn both_integrators_see_the_map_where_the_layout_says() {
    // A 4 x 2 map of distinct colours, read from a file; a one-pixel camera at the origin looking
    // at the centre of pixel (2, 0) (u = 5/8, v = 1/4: azimuth 45 degrees from +x towards +z, 45
    // degrees below straight up) sees it alone, at the centre of pixel (3, 1) (u = 7/8, v = 3/4)
    // that one; halfway between the centres of (2, 0) and (3, 0) (u = 3/4, along +z) their mean,
    // the lookup being bilinear; turned by 90 degrees, what the map has along (x, y, z) is seen
    // along (z, y, -x).
    let dir = tempfile::tempdir().unwrap();
    let pixels = (0..8).map(|i| Vec3::new(i as f32, 10.0 + i as f32, 0.5)).collect();
    let map = EnvironmentMap { path: "four.exr".into(), width: 4, height: 2, pixels };
    let path = dir.path().join("four.exr");
    write_map(&map, &path);
    let h = std::f32::consts::FRAC_1_SQRT_2;
    let between = (map.get(2, 0) + map.get(3, 0)) * 0.5;
    for integrator in ["whitted", "path"] {
        for (look_at, rotation, want) in [
            ([0.5, h, 0.5], 0.0, map.get(2, 0)),
            ([-0.5, -h, 0.5], 0.0, map.get(3, 1)),
            ([0.0, h, h], 0.0, between),
            ([0.5, h, -0.5], 90.0, map.get(2, 0)),
        ] {
            let s = scene(&format!(
                "[image]\nwidth = 1\nheight = 1\nintegrator = \"{integrator}\"\n[camera]\nposition = [0, 0, 0]\n\
                 look_at = {look_at:?}\nfov = 1\n[environment]\nfile = \"{}\"\nrotation = {rotation}\nintensity = 2\n",
                path.display()
            ));
            let seen = render(&s)[0];
            assert!(
                (seen - want * 2.0).abs().max_element() < 1e-3,
                "{integrator}, looking at {look_at:?}, turned {rotation}: {seen} against {}",
                want * 2.0
            );
        }
    }
}
