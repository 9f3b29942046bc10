//! Sphere and rectangle lights against closed forms, and the path tracer's multiple importance
//! sampling against light sampling alone and BSDF sampling alone.
//!
//! A sphere of radiance `L` and radius `R` whose centre is at distance `d` from a point, at angle
//! `φ` from its normal, and entirely above its horizon, gives the irradiance `π L R² cos φ / d²`
//! (it acts as a point source of intensity `π R² L`; on the axis this is `π L sin² θmax`). A
//! diffuse surface of albedo `ρ` then reflects `ρ L R² cos φ / d²`. A rectangle of radiance `L`
//! parallel to the surface at height `h`, with the point below one corner, sides `a` and `b`,
//! gives `π L F` with the form factor
//! `F = (A / √(1 + A²) atan(B / √(1 + A²)) + B / √(1 + B²) atan(A / √(1 + B²))) / 2π`,
//! `A = a / h`, `B = b / h` (Howell's catalogue of configuration factors, C-11).

use std::f64::consts::PI;

use englobe::{AccelKind, Vec3};
use englobe_render::sampling::cosine_hemisphere;
use englobe_render::sphere_lights::SphereLights;
use englobe_render::{Renderer, build_world};
use englobe_scene::{Scene, parse_scene};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg32;

fn scene(text: &str) -> Scene {
    parse_scene(text, "test.toml".as_ref()).unwrap_or_else(|e| panic!("{e}"))
}

/// A diffuse plane y = 0 of albedo `RHO` seen at `(x, 0, z)` through the centre of a one-pixel
/// image, with `lights` (scene text) above it; direct light only.
fn plane_point(x: f32, z: f32, lights: &str) -> Scene {
    scene(&format!(
        r#"
[image]
width = 1
height = 1
samples = 1
max_depth = 1
integrator = "path"
[camera]
position = [{cx}, 3.0, {cz}]
look_at = [{x}, 0.0, {z}]
fov = 1
[materials.m]
diffuse = [{RHO}, {RHO}, {RHO}]
[materials.lamp]
diffuse = [0, 0, 0]
emission = [{L}, {L}, {L}]
[[plane]]
point = [0, 0, 0]
normal = [0, 1, 0]
material = "m"
{lights}
"#,
        cx = x - 2.5,
        cz = z - 1.5,
    ))
}

const RHO: f64 = 0.5;
const L: f64 = 2.0;

/// `n` one-sample estimates of the pixel of `s`, each with a seed of its own, and their mean and
/// standard error.
fn estimates(s: &Scene, n: u64) -> (f64, f64) {
    let world = build_world(s, AccelKind::BvhWide).unwrap();
    let mut s = s.clone();
    let values: Vec<f64> = (0..n)
        .map(|seed| {
            s.image.seed = seed;
            Renderer::new(&s, &world).render().unwrap().film.get(0, 0).x as f64
        })
        .collect();
    mean_and_error(&values)
}

fn mean_and_error(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

#[test]
fn a_sphere_light_lights_a_diffuse_plane_as_the_closed_form_says() {
    let (center, radius) = (Vec3::new(0.3, 1.5, -0.2), 0.4f32);
    let sphere = format!(
        "[[sphere]]\ncenter = [{}, {}, {}]\nradius = {radius}\nmaterial = \"lamp\"",
        center.x, center.y, center.z
    );
    for (x, z) in [(0.3f32, -0.2f32), (1.0, 0.5), (-1.5, 0.0)] {
        let to_center = center - Vec3::new(x, 0.0, z);
        let d2 = to_center.length_squared() as f64;
        let cos = to_center.y as f64 / d2.sqrt();
        let expected = RHO * L * (radius as f64).powi(2) * cos / d2;
        let (mean, error) = estimates(&plane_point(x, z, &sphere), 2000);
        eprintln!("({x}, {z}): {mean:.5} +- {error:.5}, expected {expected:.5}");
        assert!(error < 0.02 * expected, "the sphere is sampled: {error}");
        assert!((mean - expected).abs() < 4.0 * error + 1e-4 * expected, "({x}, {z}): {mean} against {expected}");
    }
}

#[test]
fn light_sampling_alone_and_bsdf_sampling_alone_find_the_same_light() {
    // The techniques that the path tracer combines, one at a time, at a point of the plane below
    // and beside a sphere light: both are unbiased, and agree with the closed form.
    let (center, radius) = (Vec3::new(0.8, 1.2, 0.1), 0.5f32);
    let s = scene(&format!(
        "[image]\nwidth = 1\nheight = 1\n[camera]\nposition = [0, 1, -3]\nlook_at = [0, 0, 0]\n\
         [materials.lamp]\nemission = [{L}, {L}, {L}]\n[[sphere]]\ncenter = [{}, {}, {}]\nradius = {radius}\nmaterial = \"lamp\"\n",
        center.x, center.y, center.z
    ));
    let lights = SphereLights::of(&s);
    let p = Vec3::ZERO;
    let to_center = center - p;
    let d2 = to_center.length_squared() as f64;
    let expected = RHO * L * (radius as f64).powi(2) * (to_center.y as f64 / d2.sqrt()) / d2;
    let mut rng = Pcg32::seed_from_u64(3);
    let n = 200_000;
    let light_only: Vec<f64> = (0..n)
        .map(|_| {
            let l = lights.sample(p, rng.random(), rng.random(), rng.random()).unwrap();
            let cos = l.direction.y.max(0.0) as f64;
            RHO / PI * l.radiance.x as f64 * cos / l.pdf as f64
        })
        .collect();
    let bsdf_only: Vec<f64> = (0..n)
        .map(|_| {
            let d = cosine_hemisphere(Vec3::Y, rng.random(), rng.random());
            let sphere = englobe::Sphere::new(center, radius);
            let hits = sphere.roots(&englobe::Ray::new(p, d)).is_some_and(|(t0, t1)| t1 > 0.0 && t0.max(0.0) < t1);
            if hits { RHO * L } else { 0.0 }
        })
        .collect();
    let (light_mean, light_error) = mean_and_error(&light_only);
    let (bsdf_mean, bsdf_error) = mean_and_error(&bsdf_only);
    eprintln!(
        "expected {expected:.5}; light {light_mean:.5} +- {light_error:.5}; BSDF {bsdf_mean:.5} +- {bsdf_error:.5}"
    );
    assert!((light_mean - expected).abs() < 4.0 * light_error + 1e-6, "{light_mean}");
    assert!((bsdf_mean - expected).abs() < 4.0 * bsdf_error, "{bsdf_mean}");
    assert!(light_error < 0.2 * bsdf_error, "light sampling is the better technique here");
    // The renderer's combination of the two agrees with both.
    let lamp = format!(
        "[[sphere]]\ncenter = [{}, {}, {}]\nradius = {radius}\nmaterial = \"lamp\"",
        center.x, center.y, center.z
    );
    let (mis, mis_error) = estimates(&plane_point(0.0, 0.0, &lamp), 2000);
    let with = |e: f64| (mis_error * mis_error + e * e).sqrt();
    assert!((mis - light_mean).abs() < 4.0 * with(light_error), "MIS {mis} against light sampling {light_mean}");
    assert!((mis - bsdf_mean).abs() < 4.0 * with(bsdf_error), "MIS {mis} against BSDF sampling {bsdf_mean}");
}

/// The form factor from a point to a rectangle `a` x `b` parallel to it at height `h`, the point
/// below one corner.
fn corner_form_factor(a: f64, b: f64, h: f64) -> f64 {
    let (x, y) = (a / h, b / h);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * PI)
}

#[test]
fn a_rectangle_light_lights_a_diffuse_plane_as_the_form_factor_says() {
    // A 1.2 x 0.8 rectangle at height 1, facing down (edge1 x edge2 = -y), centred above (0.1, 0, 0.2).
    let (a, b, h) = (1.2f64, 0.8f64, 1.0f64);
    let rect =
        "[[rectangle]]\ncorner = [-0.5, 1.0, -0.2]\nedge1 = [1.2, 0, 0]\nedge2 = [0, 0, 0.8]\nmaterial = \"lamp\"";
    // Below the centre: four quarter rectangles; below a corner: one.
    for ((x, z), factor) in
        [((0.1f32, 0.2f32), 4.0 * corner_form_factor(a / 2.0, b / 2.0, h)), ((-0.5, -0.2), corner_form_factor(a, b, h))]
    {
        let expected = RHO * L * factor;
        let (mean, error) = estimates(&plane_point(x, z, rect), 2000);
        eprintln!("({x}, {z}): {mean:.5} +- {error:.5}, expected {expected:.5}");
        assert!((mean - expected).abs() < 4.0 * error + 1e-4 * expected, "({x}, {z}): {mean} against {expected}");
    }
    // Facing up instead (edges swapped), it lights nothing below: rectangles emit on one side.
    let up = rect.replace("edge1 = [1.2, 0, 0]\nedge2 = [0, 0, 0.8]", "edge1 = [0, 0, 0.8]\nedge2 = [1.2, 0, 0]");
    assert_eq!(estimates(&plane_point(0.1, 0.2, &up), 20).0, 0.0);
}
