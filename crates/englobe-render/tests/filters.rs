//! Pixel filters end to end: the default box renders the very image of explicit jitter over the
//! pixel, and a sharp edge seen through each filter is blurred by exactly the filter's
//! distribution function (each pixel is the fraction of its samples that land on the bright side).

use englobe::{AccelKind, Vec3};
use englobe_render::{RenderOutput, Renderer, build_world};
use englobe_scene::{Scene, parse_scene};

fn scene(text: &str) -> Scene {
    parse_scene(text, "test.toml".as_ref()).unwrap_or_else(|e| panic!("{e}"))
}

fn render(scene: &Scene) -> RenderOutput {
    let world = build_world(scene, AccelKind::BvhWide).unwrap();
    Renderer::new(scene, &world).render().unwrap()
}

/// A 16 x 2 orthographic view of a glowing half-plane whose edge falls on the boundary between
/// pixel columns 7 and 8, the glow on the left.
fn edge(filter: &str, samples: u32) -> Scene {
    scene(&format!(
        r#"
[image]
width = 16
height = 2
samples = {samples}
{filter}
[camera]
position = [0, 0, -5]
look_at = [0, 0, 0]
projection = "orthographic"
view_height = 2
[materials.glow]
diffuse = [0, 0, 0]
emission = [1, 1, 1]
[[triangle]]
vertices = [[0, -100, 0], [0, 100, 0], [100, 0, 0]]
material = "glow"
"#
    ))
}

/// The integral of `shape` over `[-r, t]` divided by its integral over `[-r, r]` (Simpson's rule
/// on 20 000 intervals: independent of the renderer's sampling code).
fn distribution(shape: impl Fn(f64) -> f64, r: f64, t: f64) -> f64 {
    let integral = |a: f64, b: f64| {
        if b <= a {
            return 0.0;
        }
        let n = 20_000;
        let h = (b - a) / n as f64;
        let s: f64 = (0..=n)
            .map(|i| {
                shape(a + i as f64 * h)
                    * if i == 0 || i == n {
                        1.0
                    } else if i % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    }
            })
            .sum();
        s * h / 3.0
    };
    integral(-r, t.clamp(-r, r)) / integral(-r, r)
}

#[test]
fn the_default_filter_is_the_box_of_half_a_pixel() {
    let implicit = render(&edge("", 16));
    let explicit = render(&edge("filter = \"box\"\nfilter_radius = 0.5", 16));
    let bits =
        |o: &RenderOutput| o.film.pixels().iter().flat_map(|p| p.to_array().map(f32::to_bits)).collect::<Vec<_>>();
    assert_eq!(bits(&implicit), bits(&explicit));
    let wide = render(&edge("filter = \"triangle\"\nfilter_radius = 1", 16));
    assert_ne!(bits(&implicit), bits(&wide), "a wider filter changes the picture");
}

/// A filter's shape along one axis.
type Shape = Box<dyn Fn(f64) -> f64>;

#[test]
fn an_edge_is_blurred_by_the_filters_distribution() {
    let samples = 4096;
    let gauss = |x: f64| ((-x * x / (2.0 * 0.5 * 0.5)).exp() - (-1.5f64 * 1.5 / (2.0 * 0.5 * 0.5)).exp()).max(0.0);
    let cases: [(&str, Shape, f64); 3] = [
        ("filter = \"box\"", Box::new(|_| 1.0), 0.5),
        ("filter = \"triangle\"\nfilter_radius = 2", Box::new(|x: f64| (2.0 - x.abs()).max(0.0)), 2.0),
        ("filter = \"gaussian\"", Box::new(gauss), 1.5),
    ];
    for (keys, shape, r) in cases {
        let out = render(&edge(keys, samples));
        for row in 0..2 {
            for col in 0..16u32 {
                // The sample lands left of the edge (x = 8) when col + 0.5 + offset < 8.
                let expected = distribution(&shape, r, 8.0 - (col as f64 + 0.5));
                let got = out.film.get(col, row);
                assert!(got.x == got.y && got.y == got.z);
                let sigma = (expected * (1.0 - expected) / samples as f64).sqrt();
                assert!(
                    (got.x as f64 - expected).abs() <= 5.0 * sigma + 1e-6,
                    "{keys}: column {col}: {} against {expected} (sigma {sigma})",
                    got.x
                );
            }
        }
        // The blur reaches exactly as far as the radius.
        let lit = (0..16).filter(|&c| out.film.get(c, 0) != Vec3::ZERO).count();
        assert_eq!(lit, (8.0 + r - 0.5).ceil() as usize, "{keys}");
    }
}
