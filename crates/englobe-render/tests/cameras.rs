//! The cameras against closed forms, through whole renders: an orthographic camera draws a sphere
//! with its radius in pixels wherever it stands, and a thin lens leaves the plane in focus sharp
//! and blurs the rest.

use englobe::AccelKind;
use englobe_render::{Renderer, build_world};
use englobe_scene::{Scene, parse_scene};

/// A white unit sphere at `z` (lit by the ambient term alone, so exactly 1 where it is seen) on a
/// black background, seen by `camera` (a `[camera]` table's body).
fn sphere_scene(z: f32, camera: &str, samples: u32) -> Scene {
    let text = format!(
        "[image]\nwidth = 100\nheight = 100\nsamples = {samples}\nambient = [1, 1, 1]\n\
         [camera]\nposition = [0, 0, -10]\nlook_at = [0, 0, 0]\n{camera}\n\
         [materials.white]\ndiffuse = [1, 1, 1]\n\
         [[sphere]]\ncenter = [0, 0, {z}]\nradius = 1\nmaterial = \"white\"\n"
    );
    parse_scene(&text, "camera.toml".as_ref()).unwrap_or_else(|e| panic!("{e}"))
}

fn render(scene: &Scene) -> englobe_render::RenderOutput {
    let world = build_world(scene, AccelKind::None).unwrap();
    Renderer::new(scene, &world).render().unwrap()
}

/// Pixels of the middle row brighter than half.
fn width_in_pixels(scene: &Scene) -> usize {
    let out = render(scene);
    (0..100).filter(|&x| out.film.get(x, 50).x > 0.5).count()
}

#[test]
fn an_orthographic_sphere_has_its_radius_in_pixels_at_any_distance() {
    // 100 pixels span 4 units: the sphere of radius 1 is 50 pixels across, near or far.
    for z in [-5.0, 0.0, 20.0] {
        let s = sphere_scene(z, "projection = \"orthographic\"\nview_height = 4", 1);
        assert_eq!(width_in_pixels(&s), 50, "sphere at z = {z}");
    }
    // The same sphere in perspective shrinks with distance.
    let near = width_in_pixels(&sphere_scene(-5.0, "fov = 30", 1));
    let far = width_in_pixels(&sphere_scene(20.0, "fov = 30", 1));
    assert!(near > 2 * far, "{near} and {far} pixels");
}

#[test]
fn the_orthographic_view_defaults_to_the_perspective_view_at_the_look_at_point() {
    // fov 2 atan(0.2) at distance 10: the view is 4 units high, as above.
    let fov = 2.0 * 0.2f32.atan().to_degrees();
    let s = sphere_scene(0.0, &format!("projection = \"orthographic\"\nfov = {fov}"), 1);
    assert_eq!(width_in_pixels(&s), 50);
}

#[test]
fn a_thin_lens_keeps_the_focal_plane_sharp_and_blurs_the_rest() {
    // Edge pixels: neither 0 nor 1. With the sphere's silhouette in focus (at distance 10 - 1 =
    // 9, roughly where the silhouette lies), few; focused far behind it, many.
    let blurred = |camera: &str| {
        let out = render(&sphere_scene(0.0, camera, 64));
        out.film.pixels().iter().filter(|p| p.x > 0.05 && p.x < 0.95).count()
    };
    let pinhole = blurred("fov = 30");
    let focused = blurred("fov = 30\naperture = 0.5\nfocus_distance = 9.9");
    let unfocused = blurred("fov = 30\naperture = 0.5\nfocus_distance = 40");
    assert!(focused < pinhole + pinhole / 2, "in focus: {focused} edge pixels, pinhole {pinhole}");
    assert!(unfocused > 3 * focused, "out of focus: {unfocused} edge pixels, in focus {focused}");
}

#[test]
fn view_height_is_refused_for_a_perspective_camera() {
    let text =
        "[image]\nwidth = 4\nheight = 4\n[camera]\nposition = [0, 0, -1]\nlook_at = [0, 0, 0]\nview_height = 2\n";
    let e = parse_scene(text, "c.toml".as_ref()).unwrap_err().to_string();
    assert!(e.starts_with("c.toml:7:15: `view_height` is for `projection = \"orthographic\"`"), "{e}");
}
