//! Primary rays in packets (renders that do not count their work trace a tile's camera rays
//! sixteen at a time) give the image a pixel-by-pixel render gives, bit for bit: Whitted and path
//! tracing, one sample and several, a thin lens, cut-outs (which take single rays), instances and
//! shapes beside meshes. The scenes under `scenes/` read meshes from the shared data folder.

use std::path::PathBuf;

use englobe::AccelKind;
use englobe_render::{DEFAULT_SCENE, Renderer, build_world};
use englobe_scene::{IntegratorKind, Scene, load_scene, parse_scene};

/// Renders `scene` at `width` x `height` in packets and pixel by pixel (counting work turns
/// packets off), and compares the two images bit for bit.
fn same_image(name: &str, scene: &Scene, width: u32, height: u32) {
    let world = build_world(scene, AccelKind::BvhWide).unwrap();
    let packets = Renderer::new(scene, &world).size(width, height).render().unwrap();
    let single = Renderer::new(scene, &world).size(width, height).count_work(true).render().unwrap();
    let bits = |p: &[englobe::Vec3]| p.iter().flat_map(|v| v.to_array().map(f32::to_bits)).collect::<Vec<_>>();
    assert_eq!(bits(packets.film.pixels()), bits(single.film.pixels()), "{name}: the images differ");
    assert!(packets.stats.total().rays > 0);
}

fn file(name: &str) -> Scene {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes").join(name);
    load_scene(&path).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn packets_render_the_images_of_single_rays() {
    let default = parse_scene(DEFAULT_SCENE, "default.toml".as_ref()).unwrap();
    // Sizes that are not multiples of the tile or of the packet's four pixels.
    same_image("default", &default, 83, 61);
    let mut several = default.clone();
    several.image.samples = 3;
    same_image("default, 3 samples", &several, 45, 34);
    let mut lens = default.clone();
    lens.camera.lens_radius = 0.05;
    lens.camera.focus_distance = 4.0;
    lens.image.samples = 2;
    same_image("default, thin lens", &lens, 40, 30);
    let mut path = default.clone();
    path.image.integrator = IntegratorKind::Path;
    path.image.samples = 2;
    same_image("default, path tracing", &path, 42, 31);
    for name in ["bunny.toml", "bunny-field.toml", "cornell-box-path.toml", "textured-ground.toml"] {
        same_image(name, &file(name), 64, 48);
    }
}
