//! The film's options that change pixels: the clamp of each sample's radiance against fireflies.

use englobe::{AccelKind, Vec3};
use englobe_render::render::clamp_sample;
use englobe_render::{Renderer, build_world};
use englobe_scene::parse_scene;

#[test]
fn the_clamp_scales_a_bright_sample_down_keeping_its_hue() {
    assert_eq!(clamp_sample(Vec3::new(20.0, 10.0, 5.0), 10.0), Vec3::new(10.0, 5.0, 2.5));
    assert_eq!(clamp_sample(Vec3::new(0.5, 9.0, 10.0), 10.0), Vec3::new(0.5, 9.0, 10.0));
    assert_eq!(clamp_sample(Vec3::new(f32::INFINITY, 1.0, 0.0), 4.0), Vec3::new(4.0, 1.0, 0.0));
}

#[test]
fn with_a_clamp_no_pixel_exceeds_it_and_without_one_they_do() {
    // A small, very bright lamp over a floor: bounces that find it bring samples of 500.
    let text = r#"
[image]
width = 16
height = 16
samples = 8
max_depth = 3
integrator = "path"
clamp = 2.5
[camera]
position = [0, 2, -4]
look_at = [0, 0, 0]
[materials.lamp]
diffuse = [0, 0, 0]
emission = [500, 400, 300]
[[plane]]
point = [0, 0, 0]
normal = [0, 1, 0]
[[sphere]]
center = [0, 1, 0]
radius = 0.3
material = "lamp"
"#;
    let mut s = parse_scene(text, "clamp.toml".as_ref()).unwrap();
    assert_eq!(s.image.clamp, Some(2.5));
    let world = build_world(&s, AccelKind::BvhWide).unwrap();
    let clamped = Renderer::new(&s, &world).render().unwrap().film;
    assert!(clamped.pixels().iter().all(|p| p.max_element() <= 2.5), "every sample was at most 2.5");
    // The lamp seen directly keeps its hue: 2.5 for red, 2.0 for green, 1.5 for blue.
    assert!(clamped.pixels().iter().any(|p| *p == Vec3::new(2.5, 2.0, 1.5)));
    s.image.clamp = None;
    let free = Renderer::new(&s, &world).render().unwrap().film;
    assert!(free.pixels().iter().any(|p| p.max_element() > 100.0));
}
