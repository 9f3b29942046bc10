//! The integrators against closed forms, with tolerances from the sample counts: Fresnel's
//! equations at known angles, direct light from a directional and a point light on a diffuse
//! plane, the white furnace, and the path tracer's convergence rate (the emissive furnaces are in
//! `path.rs`).
//!
//! Light units are the scene format's (see englobe-render's `shading`): a diffuse surface of
//! albedo `rho` lit by a point light of intensity `I` at distance `d` and angle `theta` reflects
//! `rho I cos(theta) / d^2`, which is pbrt's `rho I' cos / (pi d^2)` for a radiant intensity
//! `I' = pi I`; the closed forms below are written in those units.

use englobe::{AccelKind, Vec3};
use englobe_render::optics::{fresnel_dielectric, refract};
use englobe_render::{Renderer, build_world};
use englobe_scene::{IntegratorKind, Scene, parse_scene};

fn scene(text: &str) -> Scene {
    parse_scene(text, "test.toml".as_ref()).unwrap_or_else(|e| panic!("{e}"))
}

fn mean_red(s: &Scene, integrator: IntegratorKind) -> f64 {
    let world = build_world(s, AccelKind::BvhWide).unwrap();
    let out = Renderer::new(s, &world).integrator(integrator).render().unwrap();
    out.film.pixels().iter().map(|p| p.x as f64).sum::<f64>() / out.film.pixels().len() as f64
}

#[test]
fn fresnel_of_glass_at_known_angles() {
    let eta = 1.0 / 1.5; // from air into glass
    let at = |degrees: f64| {
        let i = (degrees as f32).to_radians();
        let d = Vec3::new(i.sin(), -i.cos(), 0.0);
        let (t, cos_t) = refract(d, Vec3::Y, eta).expect("air to glass always refracts");
        (fresnel_dielectric(i.cos(), cos_t, eta), t)
    };
    let (f0, _) = at(0.0);
    assert!((f0 - 0.04).abs() < 1e-6, "normal incidence: {f0}");
    let (f80, t80) = at(80.0);
    assert!((f80 as f64 - 0.387704354691473).abs() < 1e-5, "80 degrees: {f80}");
    let refracted = (t80.x as f64).asin().to_degrees();
    assert!((refracted - 41.03641052520335).abs() < 1e-4, "refraction angle {refracted}");
    // From inside: total internal reflection beyond asin(1 / 1.5) = 41.8103 degrees.
    let inside = |degrees: f32| {
        let i = degrees.to_radians();
        refract(Vec3::new(i.sin(), -i.cos(), 0.0), Vec3::Y, 1.5)
    };
    assert!(inside(41.80).is_some() && inside(41.82).is_none());
}

/// A diffuse plane y = 0 of albedo 0.5 seen at `point` by a camera above it, through the centre
/// of a one-pixel image (one sample goes through the pixel's centre), lit by `light`.
fn lit_plane(point: [f32; 2], light: &str, integrator: &str) -> Scene {
    scene(&format!(
        r#"
[image]
width = 1
height = 1
samples = 1
integrator = "{integrator}"
max_depth = 1
[camera]
position = [{x}, 3.0, {z}]
look_at = [{x}, 0.0, {z}]
up = [0, 0, 1]
fov = 1
[materials.m]
diffuse = [0.5, 0.5, 0.5]
[[plane]]
point = [0, 0, 0]
normal = [0, 1, 0]
material = "m"
{light}
"#,
        x = point[0],
        z = point[1],
    ))
}

#[test]
fn direct_light_on_a_diffuse_plane_matches_the_closed_forms() {
    for integrator in ["whitted", "path"] {
        let kind = if integrator == "path" { IntegratorKind::Path } else { IntegratorKind::Whitted };
        // A directional light of radiance E at 60 degrees from the normal: rho E cos.
        let sun = "[[directional_light]]\ndirection = [0.8660254, -0.5, 0.0]\nintensity = 2.0";
        let got = mean_red(&lit_plane([0.3, -0.2], sun, integrator), kind);
        assert!((got - 0.5 * 2.0 * 0.5).abs() < 1e-5, "{integrator}, directional: {got}");
        // A point light of intensity I at height h, offset x: rho I h / (h^2 + x^2)^1.5.
        for (h, x) in [(1.0f64, 0.0f64), (2.0, 1.5), (0.5, 3.0)] {
            let lamp = format!("[[point_light]]\nposition = [{x}, {h}, 0.0]\nintensity = 4.0");
            let got = mean_red(&lit_plane([0.0, 0.0], &lamp, integrator), kind);
            let expected = 0.5 * 4.0 * h / (h * h + x * x).powf(1.5);
            assert!(
                (got - expected).abs() < 1e-5 * expected.max(1.0),
                "{integrator}, h {h}, x {x}: {got} against {expected}"
            );
        }
    }
}

/// A small room lit by an emissive square (two triangles) under its ceiling: area light,
/// shadows, inter-reflection.
fn lit_room(samples: u32) -> Scene {
    scene(&format!(
        r#"
[image]
width = 24
height = 24
samples = {samples}
max_depth = 6
integrator = "path"
[camera]
position = [0.0, 1.0, -2.6]
look_at = [0.0, 0.9, 0.0]
fov = 50
[materials.white]
diffuse = [0.7, 0.7, 0.7]
[materials.red]
diffuse = [0.7, 0.1, 0.1]
[materials.lamp]
diffuse = [0.0, 0.0, 0.0]
emission = [3.0, 3.0, 3.0]
[[plane]]
point = [0, 0, 0]
normal = [0, 1, 0]
material = "white"
[[plane]]
point = [0, 2, 0]
normal = [0, -1, 0]
material = "white"
[[plane]]
point = [-1, 0, 0]
normal = [1, 0, 0]
material = "red"
[[plane]]
point = [0, 0, 1]
normal = [0, 0, -1]
material = "white"
[[box]]
min = [-0.2, 0.0, -0.1]
max = [0.5, 0.8, 0.5]
material = "white"
[[triangle]]
vertices = [[-0.6, 1.98, -0.5], [0.6, 1.98, 0.6], [0.6, 1.98, -0.5]]
material = "lamp"
[[triangle]]
vertices = [[-0.6, 1.98, -0.5], [-0.6, 1.98, 0.6], [0.6, 1.98, 0.6]]
material = "lamp"
"#
    ))
}

#[test]
fn the_path_tracer_converges_as_one_over_the_sample_count() {
    let render = |samples: u32, seed: u64| {
        let mut s = lit_room(samples);
        s.image.seed = seed;
        let world = build_world(&s, AccelKind::BvhWide).unwrap();
        Renderer::new(&s, &world).render().unwrap().film
    };
    // The reference has a seed of its own, so that its noise is independent of the estimates'.
    let reference = render(4096, 1_000);
    let mse = |samples: u32| {
        // Averaged over four independent seeds: one image's squared error is itself noisy.
        let seeds = 4;
        (0..seeds)
            .map(|seed| {
                let f = render(samples, seed);
                let n = f.pixels().len() as f64;
                f.pixels()
                    .iter()
                    .zip(reference.pixels())
                    .map(|(a, b)| (*a - *b).length_squared() as f64 / 3.0)
                    .sum::<f64>()
                    / n
            })
            .sum::<f64>()
            / seeds as f64
    };
    let points: Vec<(f64, f64)> = [4u32, 8, 16, 32, 64].iter().map(|&s| ((s as f64).ln(), mse(s).ln())).collect();
    // The least-squares slope of log MSE against log spp: an independent estimate of n samples has
    // an expected squared error sigma^2 (1/n + 1/4096), slope -1 (-0.99 with the reference's own
    // noise) within the noise of 576 pixels and four seeds.
    let n = points.len() as f64;
    let (mx, my) = (points.iter().map(|p| p.0).sum::<f64>() / n, points.iter().map(|p| p.1).sum::<f64>() / n);
    let slope = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
        / points.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
    eprintln!("log-log slope of the MSE: {slope:.3}");
    assert!((-1.15..=-0.85).contains(&slope), "log-log slope {slope}: {points:?}");
}

#[test]
fn in_a_white_furnace_every_object_vanishes() {
    // Under a uniform sky of radiance 1, objects that absorb nothing (white diffuse, a perfect
    // mirror, clear glass) return every path's light: each pixel is 1, whatever the material.
    // Paths that reach the maximum depth before escaping lose their light, so the mean may fall
    // short by that alone; energy is never created.
    let s = scene(
        r#"
[image]
width = 24
height = 24
samples = 16
max_depth = 64
integrator = "path"
background = [1.0, 1.0, 1.0]
[camera]
position = [0, 0.5, -4]
look_at = [0, 0.3, 0]
fov = 50
[materials.white]
diffuse = [1.0, 1.0, 1.0]
[materials.mirror]
diffuse = [0.0, 0.0, 0.0]
reflectivity = 1.0
[materials.glass]
diffuse = [0.0, 0.0, 0.0]
transparency = 1.0
ior = 1.5
[[sphere]]
center = [-0.9, 0.5, 0]
radius = 0.6
material = "white"
[[sphere]]
center = [0.8, 0.5, 0.2]
radius = 0.6
material = "glass"
[[box]]
min = [-0.4, -0.3, 0.6]
max = [0.4, 1.2, 1.0]
material = "mirror"
[[box]]
min = [-2.0, -0.6, -1.0]
max = [2.0, -0.3, 2.0]
material = "white"
"#,
    );
    let world = build_world(&s, AccelKind::BvhWide).unwrap();
    let out = Renderer::new(&s, &world).render().unwrap();
    let values: Vec<f64> = out.film.pixels().iter().flat_map(|p| p.to_array()).map(f64::from).collect();
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    let max = values.iter().copied().fold(0.0, f64::max);
    assert!(max <= 1.0 + 1e-4, "energy created: a pixel of {max}");
    assert!(mean > 0.995, "mean {mean}: light lost");
}
