//! Adaptive depth (Hall and Greenberg 1983): between two parallel mirrors of reflectivity 1/2, a
//! ray's contribution halves at each bounce, so with `min_contribution = 0.01` the chain stops
//! after the 6th reflected ray (1/2^6 = 0.0156 >= 0.01 > 1/2^7) instead of at `max_depth`, and
//! each pixel is the closed form of the chain it keeps; off (the default), every ray is cast.

use englobe::AccelKind;
use englobe_render::{RayKind, Renderer, build_world};
use englobe_scene::{Scene, parse_scene};

fn corridor(min_contribution: Option<f32>) -> Scene {
    let option = min_contribution.map_or(String::new(), |c| format!("min_contribution = {c}"));
    let text = format!(
        r#"
[image]
width = 8
height = 8
max_depth = 40
background = [1.0, 1.0, 1.0]
ambient = [1.0, 1.0, 1.0]
{option}

[camera]
position = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, 1.0]
fov = 10

[materials.mirror]
diffuse = [0.2, 0.2, 0.2]
reflectivity = 0.5

[[plane]]
point = [0.0, 0.0, 1.0]
normal = [0.0, 0.0, -1.0]
material = "mirror"

[[plane]]
point = [0.0, 0.0, -1.0]
normal = [0.0, 0.0, 1.0]
material = "mirror"
"#
    );
    parse_scene(&text, "corridor.toml".as_ref()).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn the_chain_of_reflections_stops_where_its_contribution_falls_below_the_threshold() {
    let render = |scene: &Scene| {
        let world = build_world(scene, AccelKind::BvhWide).unwrap();
        Renderer::new(scene, &world).count_work(true).render().unwrap()
    };
    let pixels = 64;
    let full = render(&corridor(None));
    assert_eq!(full.stats.kind(RayKind::Reflected).rays, 40 * pixels, "every ray up to max_depth");
    let cut = render(&corridor(Some(0.01)));
    assert_eq!(cut.stats.kind(RayKind::Reflected).rays, 6 * pixels, "six reflections, then 1/2^7 < 0.01");
    assert_eq!(cut.stats.kind(RayKind::Primary).rays, pixels);
    // Each hit adds ambient x diffuse x (1 - kr) = 0.1 and passes on half of what it sees: a
    // chain of n + 1 hits gives 0.1 (1 - 1/2^(n+1)) / (1 - 1/2). What adaptive depth leaves out is
    // below the threshold: 0.2 / 2^7 against 0.2 / 2^41.
    let chain = |hits: i32| 0.2 * (1.0 - 0.5f64.powi(hits));
    for (a, b) in full.film.pixels().iter().zip(cut.film.pixels()) {
        assert!((a.x as f64 - chain(41)).abs() < 1e-6, "{a}");
        assert!((b.x as f64 - chain(7)).abs() < 1e-6, "{b}");
    }
}

#[test]
fn the_threshold_is_a_fraction() {
    let text = "[image]\nwidth = 4\nheight = 4\nmin_contribution = 1.5\n[camera]\nposition = [0, 0, 0]\nlook_at = [0, 0, 1]\nfov = 40\n";
    let e = parse_scene(text, "bad.toml".as_ref()).unwrap_err().to_string();
    assert!(e.contains("bad.toml:4") && e.contains("between 0 and 1"), "{e}");
}
