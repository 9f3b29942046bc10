//! End-to-end rendering: determinism across thread counts, exact optics checks, a pixel whose
//! colour can be computed by hand, the cost AOV and rendering a regular sample of the pixels.

use englobe::{AccelKind, Vec3};
use englobe_render::film::encode_srgb8;
use englobe_render::{DEFAULT_SCENE, RayKind, RenderOutput, Renderer, build_world};
use englobe_scene::{Scene, parse_scene};

fn scene(text: &str) -> Scene {
    parse_scene(text, "test.toml".as_ref()).unwrap_or_else(|e| panic!("{e}"))
}

fn render_on(scene: &Scene, threads: usize) -> RenderOutput {
    let world = build_world(scene, AccelKind::None).unwrap();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| Renderer::new(scene, &world).count_work(true).render().unwrap())
}

#[test]
fn default_scene_renders_with_every_kind_of_ray() {
    let s = scene(DEFAULT_SCENE);
    let world = build_world(&s, AccelKind::None).unwrap();
    let out = Renderer::new(&s, &world).size(80, 60).count_work(true).render().unwrap();
    assert!(out.complete);
    for kind in [RayKind::Primary, RayKind::Shadow, RayKind::Reflected, RayKind::Refracted] {
        assert!(out.stats.kind(kind).rays > 0, "no {} rays", kind.name());
    }
    assert_eq!(out.stats.kind(RayKind::Bounce).rays, 0, "Whitted's recursion never bounces diffusely");
    assert_eq!(out.stats.kind(RayKind::Primary).rays, 80 * 60 * s.image.samples as u64);
    // Brute force tests each of the 6 objects once per closest-hit ray.
    let primary = out.stats.kind(RayKind::Primary);
    assert_eq!(primary.exact_tests, primary.rays * 6);
    let bytes = out.film.to_srgb8();
    let distinct: std::collections::HashSet<_> = bytes.chunks(3).collect();
    assert!(distinct.len() > 100, "a real picture has many colours, got {}", distinct.len());
}

#[test]
fn one_and_two_threads_give_identical_images_and_counts() {
    let mut s = scene(DEFAULT_SCENE);
    s.image.width = 96;
    s.image.height = 72;
    s.image.samples = 3;
    let one = render_on(&s, 1);
    let two = render_on(&s, 2);
    assert_eq!(one.film.to_srgb8(), two.film.to_srgb8());
    assert_eq!(one.film.pixels(), two.film.pixels(), "even the linear values are identical");
    assert_eq!(one.stats, two.stats);
    let again = render_on(&s, 2);
    assert_eq!(again.film.pixels(), two.film.pixels(), "and across runs");
}

/// A backdrop whose colour does not depend on exactly where a ray lands on it: emissive and
/// ambient-lit surfaces only, no light sources (so no shadows either).
const BACKDROP: &str = r#"
[image]
width = 61
height = 47
max_depth = 6
background = [0.1, 0.2, 0.3]
ambient = [0.5, 0.5, 0.5]

[camera]
position = [0, 0, -6]
look_at = [0, 0, 0]

[materials.wall]
diffuse = [0.9, 0.3, 0.2]
[materials.lamp]
diffuse = [0, 0, 0]
emission = [0.2, 0.9, 0.4]
[materials.clear]
diffuse = [0, 0, 0]
transparency = 1.0
ior = 1.0

[[box]]
min = [-3, -3, 4]
max = [0, 3, 5]
material = "wall"

[[triangle]]
vertices = [[0, -3, 3], [3, -3, 3], [0, 3, 3]]
material = "lamp"

[[sphere]]
center = [1.5, 1.5, 2]
radius = 0.5
material = "wall"
"#;

#[test]
fn a_sphere_of_index_one_is_invisible() {
    let without = scene(BACKDROP);
    let with = scene(&format!("{BACKDROP}\n[[sphere]]\ncenter = [0, 0, 0]\nradius = 1.6\nmaterial = \"clear\"\n"));
    let a = render_on(&without, 2);
    let b = render_on(&with, 2);
    let refracted = b.stats.kind(RayKind::Refracted).rays;
    assert!(refracted > 1000, "the clear sphere must cover a good part of the image ({refracted} refracted rays)");
    assert_eq!(a.stats.kind(RayKind::Refracted).rays, 0);
    assert_eq!(a.film.pixels(), b.film.pixels(), "the image must be exactly the same");
}

#[test]
fn a_lit_sphere_centre_has_the_colour_computed_by_hand() {
    // A point light at the eye and a sphere straight ahead: at the centre pixel the normal, the
    // view and the light direction coincide, so the radiance is diffuse * intensity / d^2 with
    // d = 10 - 2 = 8. The odd image size puts a pixel centre exactly on the axis; the only error
    // left is f32 rounding of unit vectors (relative 1e-6), far below half a step of 8 bits.
    let s = scene(
        r#"
[image]
width = 33
height = 33
[camera]
position = [0, 0, 0]
look_at = [0, 0, 1]
[materials.m]
diffuse = [0.25, 0.5, 0.75]
[[point_light]]
position = [0, 0, 0]
intensity = 32
[[sphere]]
center = [0, 0, 10]
radius = 2
material = "m"
"#,
    );
    let out = render_on(&s, 1);
    let expected = Vec3::new(0.25, 0.5, 0.75) * 32.0 / 64.0;
    let got = out.film.get(16, 16);
    assert!((got - expected).abs().max_element() < 1e-5, "{got} vs {expected}");
    let bytes = out.film.to_srgb8();
    let i = (16 * 33 + 16) * 3;
    assert_eq!(&bytes[i..i + 3], &[encode_srgb8(expected.x), encode_srgb8(expected.y), encode_srgb8(expected.z)]);
    assert_eq!(out.film.get(0, 0), Vec3::ZERO, "corners see the black background");
}

#[test]
fn a_mirror_shows_what_lies_at_the_mirrored_angle() {
    // A horizontal mirror at y = 0 and an emissive sphere above it. The camera looks down at the
    // mirror; the pixel whose ray reflects toward the sphere's centre shows the sphere.
    let s = scene(
        r#"
[image]
width = 101
height = 101
max_depth = 2
[camera]
position = [0, 2, -4]
look_at = [0, 0, 0]
fov = 40
[materials.mirror]
diffuse = [0, 0, 0]
reflectivity = 1.0
[materials.lamp]
diffuse = [0, 0, 0]
emission = [1, 0.5, 0.25]
[[plane]]
point = [0, 0, 0]
normal = [0, 1, 0]
material = "mirror"
[[sphere]]
center = [0, 2, 4]
radius = 0.4
material = "lamp"
"#,
    );
    let out = render_on(&s, 2);
    // By symmetry the sphere appears where its mirror image (0, -2, 4) would be seen, which is
    // straight along the camera's view direction (0, -2, 4): the centre pixel.
    assert_eq!(out.film.get(50, 50), Vec3::new(1.0, 0.5, 0.25));
    assert_eq!(out.film.get(50, 10), Vec3::ZERO, "above the horizon: background");
    assert!(out.stats.kind(RayKind::Reflected).rays > 0);
}

#[test]
fn glass_totally_reflects_past_the_critical_angle() {
    // A ray inside glass (index 1.5) meeting the surface at 60 degrees (critical: 41.8) is
    // reflected entirely: it never refracts out, whatever it would see outside.
    let s = scene(
        r#"
[image]
width = 1
height = 1
max_depth = 1
background = [1, 1, 1]
[camera]
position = [0, 0, 0]
look_at = [0.8660254, -0.5, 0]
fov = 1
[materials.glass]
diffuse = [0, 0, 0]
transparency = 1.0
ior = 1.5
[[box]]
min = [-10, -1, -10]
max = [10, 1, 10]
material = "glass"
"#,
    );
    let out = render_on(&s, 1);
    assert_eq!(out.stats.kind(RayKind::Refracted).rays, 0, "no ray leaves the glass");
    assert_eq!(out.stats.kind(RayKind::Reflected).rays, 1);
}

#[test]
fn absurd_sizes_are_refused_before_rendering() {
    let s = scene(DEFAULT_SCENE);
    let world = build_world(&s, AccelKind::None).unwrap();
    assert!(Renderer::new(&s, &world).size(0, 10).render().is_err());
    assert!(Renderer::new(&s, &world).size(1 << 20, 1 << 20).render().is_err());
    assert!(Renderer::new(&s, &world).samples(0).render().is_err());
}

#[test]
fn cost_is_recorded_only_when_asked_and_adds_up_to_the_counts() {
    let scene = scene(DEFAULT_SCENE);
    let world = build_world(&scene, AccelKind::BvhSeedOrdered).unwrap();
    let plain = Renderer::new(&scene, &world).size(40, 30).samples(1).render().unwrap();
    assert!(plain.cost.is_none());
    let out = Renderer::new(&scene, &world).size(40, 30).samples(1).record_cost(true).render().unwrap();
    let cost = out.cost.expect("recorded");
    let total = out.stats.total();
    assert_eq!(cost.total(), total.nodes_visited + total.exact_tests);
    assert!(cost.values().iter().all(|&c| c > 0), "every pixel tests at least the plane");
    assert_eq!(out.film, plain.film, "recording the cost does not change the image");
}

#[test]
fn a_pixel_stride_renders_the_same_pixels_and_only_them() {
    let scene = scene(DEFAULT_SCENE);
    let world = build_world(&scene, AccelKind::None).unwrap();
    let full = Renderer::new(&scene, &world).size(37, 29).count_work(true).render().unwrap();
    let sample = Renderer::new(&scene, &world).size(37, 29).count_work(true).pixel_stride(4).render().unwrap();
    for y in 0..29 {
        for x in 0..37 {
            let expected = if x % 4 == 0 && y % 4 == 0 { full.film.get(x, y) } else { Vec3::ZERO };
            assert_eq!(sample.film.get(x, y), expected, "pixel ({x}, {y})");
        }
    }
    let primary = sample.stats.kind(RayKind::Primary).rays;
    assert_eq!(primary, 10 * 8 * scene.image.samples as u64);
}

#[test]
fn a_render_by_passes_writes_the_bytes_of_the_tile_renderer() {
    let mut s = scene(DEFAULT_SCENE);
    s.image.width = 50;
    s.image.height = 37;
    let world = build_world(&s, AccelKind::BvhWide).unwrap();
    for (samples, integrator) in [
        (1, englobe_scene::IntegratorKind::Whitted),
        (3, englobe_scene::IntegratorKind::Whitted),
        (4, englobe_scene::IntegratorKind::Path),
    ] {
        let r = Renderer::new(&s, &world).samples(samples).integrator(integrator).count_work(true);
        let tiles = r.render().unwrap();
        let passes = r.render_passes(None).unwrap();
        assert!(passes.complete && passes.samples_done == samples);
        let bits =
            |o: &RenderOutput| o.film.pixels().iter().flat_map(|p| p.to_array().map(f32::to_bits)).collect::<Vec<_>>();
        assert_eq!(bits(&tiles), bits(&passes), "{samples} samples, {integrator:?}");
        assert_eq!(tiles.stats.total(), passes.stats.total());
    }
}

#[test]
fn a_render_by_passes_stopped_early_holds_its_complete_passes() {
    let mut s = scene(DEFAULT_SCENE);
    s.image.width = 40;
    s.image.height = 30;
    let world = build_world(&s, AccelKind::BvhWide).unwrap();
    // Cancelled after the third pass: the image of a 3-sample render.
    let flag = std::sync::atomic::AtomicBool::new(false);
    let stop_after_3 = |done: usize, _: usize| {
        if done == 3 {
            flag.store(true, std::sync::atomic::Ordering::SeqCst);
        }
    };
    let stopped = Renderer::new(&s, &world)
        .samples(64)
        .on_progress(&stop_after_3)
        .cancel_flag(&flag)
        .render_passes(None)
        .unwrap();
    assert!(!stopped.complete);
    assert_eq!(stopped.samples_done, 3);
    let three = Renderer::new(&s, &world).samples(3).render().unwrap();
    assert_eq!(stopped.film.pixels(), three.film.pixels());
    // A deadline already passed: no pass, an empty film.
    let none = Renderer::new(&s, &world).samples(8).render_passes(Some(std::time::Instant::now())).unwrap();
    assert_eq!((none.samples_done, none.complete), (0, false));
}
