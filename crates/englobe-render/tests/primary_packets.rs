//! Primary rays in packets (renders that do not count their work trace a tile's camera rays
//! sixteen at a time, and Whitted's shadow rays of those hits toward each light too) give the image
//! a pixel-by-pixel render gives, bit for bit, and cast as many rays of each kind: Whitted and path
//! tracing, one sample and several, a thin lens, lights behind surfaces, mirrors past the packet's
//! hits, cut-outs (which take single rays), instances and shapes beside meshes. The scenes under
//! `scenes/` read meshes from the shared data folder.

use std::path::PathBuf;

use englobe::AccelKind;
use englobe_render::{DEFAULT_SCENE, RayKind, Renderer, build_world};
use englobe_scene::{IntegratorKind, Scene, load_scene, parse_scene};

/// Renders `scene` at `width` x `height` in packets and pixel by pixel (counting work turns
/// packets off), and compares the two images bit for bit.
fn same_image(name: &str, scene: &Scene, width: u32, height: u32) {
    let world = build_world(scene, AccelKind::BvhWide).unwrap();
    let packets = Renderer::new(scene, &world).size(width, height).render().unwrap();
    let single = Renderer::new(scene, &world).size(width, height).count_work(true).render().unwrap();
    let bits = |p: &[englobe::Vec3]| p.iter().flat_map(|v| v.to_array().map(f32::to_bits)).collect::<Vec<_>>();
    assert_eq!(bits(packets.film.pixels()), bits(single.film.pixels()), "{name}: the images differ");
    for kind in [RayKind::Primary, RayKind::Shadow, RayKind::Reflected, RayKind::Refracted, RayKind::Bounce] {
        let (p, s) = (packets.stats.kind(kind).rays, single.stats.kind(kind).rays);
        assert_eq!(p, s, "{name}: {} {} rays in packets, {s} one by one", p, kind.name());
    }
    assert!(packets.stats.total().rays > 0);
}

fn file(name: &str) -> Scene {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes").join(name);
    load_scene(&path).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn packets_render_the_images_of_single_rays() {
    // Every world on the fast path takes packets: the bunny's through its triangle tree.
    let bunny = file("bunny.toml");
    // Sizes that are not multiples of the tile or of the packet's four pixels.
    same_image("bunny", &bunny, 83, 61);
    let mut several = bunny.clone();
    several.image.samples = 3;
    same_image("bunny, 3 samples", &several, 45, 34);
    let mut lens = bunny.clone();
    lens.camera.lens_radius = 0.02;
    lens.camera.focus_distance = 1.0;
    lens.image.samples = 2;
    same_image("bunny, thin lens", &lens, 40, 30);
    let mut path = bunny.clone();
    path.image.integrator = IntegratorKind::Path;
    path.image.samples = 2;
    same_image("bunny, path tracing", &path, 42, 31);
    // Whitted under one point light and under two lights (a point and a directional one, which
    // many surfaces turn away from), a shiny reflective glaze, boxes beside a mesh, glTF textures.
    for name in [
        "cornell-box-path.toml",
        "cornell-box.toml",
        "textured-ground.toml",
        "sponza.toml",
        "teapot-stadium.toml",
        "damaged-helmet.toml",
    ] {
        same_image(name, &file(name), 64, 48);
    }
    // No mesh (the default scene's shapes) or instances only (the field): packets walk the top
    // level together, each ray testing the shapes and instances it reaches alone.
    let default = parse_scene(DEFAULT_SCENE, "default.toml".as_ref()).unwrap();
    let field = file("bunny-field.toml");
    for scene in [&default, &field] {
        assert!(build_world(scene, AccelKind::BvhWide).unwrap().walks_packets());
    }
    same_image("default", &default, 40, 30);
    same_image("bunny-field.toml", &field, 80, 45);
}
