//! pbrt scenes rendered: the radiance englobe computes from pbrt's lights equals pbrt's closed
//! forms (so the unit conversion is right), pbrt's images are not mirrored, and the reference
//! Cornell box shows its red wall on the left and its lamp on the ceiling.

use std::path::Path;

use englobe::{AccelKind, Vec3};
use englobe_render::{ImageCamera, RenderOutput, Renderer, build_world};
use englobe_scene::Scene;
use englobe_scene::pbrt::parse;

const PI: f64 = std::f64::consts::PI;

fn scene(text: &str) -> Scene {
    parse(text, "test.pbrt".as_ref(), false).unwrap_or_else(|e| panic!("{e}"))
}

fn render(scene: &Scene) -> RenderOutput {
    let world = build_world(scene, AccelKind::BvhWide).unwrap();
    Renderer::new(scene, &world).render().unwrap()
}

/// A camera looking down at a large diffuse square of reflectance `rho` in the plane z = 0,
/// with `lights`; one sample per pixel, through the pixel's centre.
fn plane_under(lights: &str, rho: f64) -> String {
    format!(
        "LookAt 0 0 6  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\n\
         Film \"rgb\" \"integer xresolution\" 15 \"integer yresolution\" 11\n\
         Sampler \"independent\" \"integer pixelsamples\" 1\nIntegrator \"path\" \"integer maxdepth\" 5\n\
         WorldBegin\n{lights}\nMaterial \"diffuse\" \"rgb reflectance\" [{rho} {rho} {rho}]\n\
         Shape \"trianglemesh\" \"point3 P\" [-50 -50 0 50 -50 0 50 50 0 -50 50 0] \"integer indices\" [0 1 2 0 2 3]\n"
    )
}

/// Where the centre ray of pixel `(x, y)` meets the plane z = 0.
fn hit_on_plane(s: &Scene, x: u32, y: u32) -> Vec3 {
    let ray = ImageCamera::new(&s.camera, s.image.width, s.image.height).ray(x as f32 + 0.5, y as f32 + 0.5);
    ray.origin() + ray.dir() * (-ray.origin().z / ray.dir().z)
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-30)
}

#[test]
fn a_point_light_gives_pbrts_radiance() {
    // pbrt: a point light of intensity I at height h over a diffuse plane of reflectance rho gives
    // the radiance rho / pi * I * cos / d^2 = rho I h / (pi (h^2 + x^2)^1.5) at horizontal distance x.
    let (i, h, rho) = (3.0, 2.0, 0.5);
    let s = scene(&plane_under(
        &format!("LightSource \"point\" \"point3 from\" [0.3 -0.2 {h}] \"rgb I\" [{i} {i} {i}]"),
        rho,
    ));
    let out = render(&s);
    for (x, y) in [(7, 5), (0, 0), (14, 10), (3, 8)] {
        let p = hit_on_plane(&s, x, y);
        let r2 = ((p.x as f64 - 0.3).powi(2) + (p.y as f64 + 0.2).powi(2)) as f64;
        let expected = rho * i * h / (PI * (h * h + r2).powf(1.5));
        let got = out.film.get(x, y);
        assert!(relative(got.x as f64, expected) < 2e-4, "pixel ({x}, {y}) at {p}: {} against {expected}", got.x);
        assert!(got.x == got.y && got.y == got.z);
    }
}

#[test]
fn a_distant_light_gives_pbrts_radiance() {
    // Irradiance L cos(theta) from a distant light of radiance L: radiance rho / pi * L * cos.
    let (l, rho) = (2.0, 0.8);
    let s = scene(&plane_under(
        &format!("LightSource \"distant\" \"point3 from\" [1 0 1] \"point3 to\" [0 0 0] \"rgb L\" [{l} {l} {l}]"),
        rho,
    ));
    let out = render(&s);
    let expected = rho / PI * l * (PI / 4.0).cos();
    for (x, y) in [(7, 5), (1, 9)] {
        assert!(relative(out.film.get(x, y).x as f64, expected) < 1e-5, "{} against {expected}", out.film.get(x, y).x);
    }
}

#[test]
fn emitters_and_the_sky_are_seen_at_their_radiance() {
    // The plane itself emits (a black diffuse area light, facing the camera): every pixel is L.
    // Seen from behind, a one-sided light is dark; with nothing in view, the sky's L is seen.
    let emitting = "AreaLightSource \"diffuse\" \"rgb L\" [1.5 2.5 3.5]\n";
    let s = scene(&plane_under(emitting, 0.0));
    assert!(render(&s).film.pixels().iter().all(|&p| p == Vec3::new(1.5, 2.5, 3.5)));
    let s = scene(&plane_under(&format!("{emitting}ReverseOrientation"), 0.0));
    assert!(render(&s).film.pixels().iter().all(|&p| p == Vec3::ZERO));
    let sky = scene(
        "Film \"rgb\" \"integer xresolution\" 4 \"integer yresolution\" 4\nWorldBegin\n\
         LightSource \"infinite\" \"rgb L\" [0.25 0.5 1] \"float scale\" 2\n",
    );
    assert!(render(&sky).film.pixels().iter().all(|&p| p == Vec3::new(0.5, 1.0, 2.0)));
}

/// The mean colour of each half of an image of two spheres, red at world +x and blue at world
/// -x, lit from both sides of z and seen with `camera`.
fn halves(camera: &str) -> (Vec3, Vec3) {
    let s = scene(&format!(
        "{camera}\nCamera \"perspective\" \"float fov\" 30\nFilm \"rgb\" \"integer xresolution\" 40 \"integer yresolution\" 20\n\
         Sampler \"independent\" \"integer pixelsamples\" 1\nWorldBegin\n\
         LightSource \"point\" \"point3 from\" [0 0 8] \"rgb I\" [50 50 50]\n\
         LightSource \"point\" \"point3 from\" [0 0 -8] \"rgb I\" [50 50 50]\n\
         AttributeBegin\nMaterial \"diffuse\" \"rgb reflectance\" [0.9 0 0]\nTranslate 1.2 0 0\nShape \"sphere\"\nAttributeEnd\n\
         AttributeBegin\nMaterial \"diffuse\" \"rgb reflectance\" [0 0 0.9]\nTranslate -1.2 0 0\nShape \"sphere\"\nAttributeEnd\n"
    ));
    let out = render(&s);
    let mean = |cols: std::ops::Range<u32>| {
        let mut sum = Vec3::ZERO;
        for x in cols.clone() {
            for y in 0..20 {
                sum += out.film.get(x, y);
            }
        }
        sum / (cols.len() * 20) as f32
    };
    (mean(0..20), mean(20..40))
}

#[test]
fn pbrt_images_are_not_mirrored() {
    // pbrt's world is left-handed: looking down -z with +y up, +x is on the image's left
    // (LookAt's camera x is up x dir = -x).
    let (left, right) = halves("LookAt 0 0 8  0 0 0  0 1 0");
    assert!(left.x > 5.0 * left.z && right.z > 5.0 * right.x, "left {left}, right {right}");
    // Looking down +z instead, +x is on the right; and `Scale -1 1 1` mirrors either.
    let (left, right) = halves("LookAt 0 0 -8  0 0 0  0 1 0");
    assert!(left.z > 5.0 * left.x && right.x > 5.0 * right.z, "left {left}, right {right}");
    let (left, right) = halves("Scale -1 1 1\nLookAt 0 0 8  0 0 0  0 1 0");
    assert!(left.z > 5.0 * left.x && right.x > 5.0 * right.z, "left {left}, right {right}");
}

#[test]
fn the_cornell_box_has_its_red_wall_left_and_its_lamp_on_the_ceiling() {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    let shared = englobe_scene::shared_data::locate_shared(here).expect("the shared scene data");
    let mut s = englobe_scene::pbrt::load(&shared.join("scenes/cornell-bitterli/scene-v4.pbrt"), false).unwrap();
    (s.image.width, s.image.height, s.image.samples) = (64, 64, 16);
    let out = render(&s);
    let mean = |xs: std::ops::Range<u32>, ys: std::ops::Range<u32>| {
        let mut sum = Vec3::ZERO;
        for x in xs.clone() {
            for y in ys.clone() {
                sum += out.film.get(x, y);
            }
        }
        sum / (xs.len() * ys.len()) as f32
    };
    // The side walls fill the image's outer columns (from the front edge, just outside the
    // picture, to the back corners, 8 pixels in); their reflectances are red (0.63, 0.065, 0.05)
    // and green (0.14, 0.45, 0.091).
    let (left, right) = (mean(2..6, 20..44), mean(58..62, 20..44));
    assert!(left.x > 4.0 * left.y && left.x > 4.0 * left.z, "left wall {left}");
    assert!(right.y > 2.0 * right.x && right.y > 3.0 * right.z, "right wall {right}");
    // The lamp, (17, 12, 4) at y = 1.98, is the brightest spot, at the top middle, and keeps its
    // colour.
    let (mut best, mut at) = (Vec3::ZERO, (0, 0));
    for (i, p) in out.film.pixels().iter().enumerate() {
        if p.x > best.x {
            (best, at) = (*p, (i as u32 % 64, i as u32 / 64));
        }
    }
    assert!((26..39).contains(&at.0) && at.1 <= 8, "the lamp at {at:?}");
    let ratio = |a: f32, b: f32| (a / best.x - b / 17.0).abs() < 0.08;
    assert!(best.x > 6.0 && ratio(best.y, 12.0) && ratio(best.z, 4.0), "{best}");
    // The lamp lights the floor left of the short box: directly, rho / pi * E with E about
    // 17 * 0.18 m^2 * cos^2 / d^2 = 0.5 there, that is 0.12 in red, and more by inter-reflection.
    let floor = mean(8..16, 58..63);
    assert!(floor.x > 0.1 && floor.x < 0.3, "floor {floor}");
}

/// The mean of the pixels of a unit sphere of pbrt material `material` seen under a white sky
/// (pbrt's `infinite` light of radiance 1), and the standard error of that mean (pixels are
/// independent estimates). The sphere fills the image, even where pbrt's default filter (a
/// Gaussian of radius 1.5 pixels) reaches beyond its edge.
fn pbrt_furnace(material: &str) -> (f64, f64) {
    let s = scene(&format!(
        "LookAt 0 0 4  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 16\n\
         Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 16\n\
         Sampler \"independent\" \"integer pixelsamples\" 64\nIntegrator \"path\" \"integer maxdepth\" 64\n\
         WorldBegin\nLightSource \"infinite\" \"rgb L\" [1 1 1]\nMaterial {material}\nShape \"sphere\"\n"
    ));
    let values: Vec<f64> = render(&s).film.pixels().iter().map(|p| f64::from(p.element_sum()) / 3.0).collect();
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (variance / n).sqrt())
}

#[test]
fn pbrt_materials_keep_energy_in_a_white_furnace() {
    // (material, expected, bias allowed): a white Lambertian, a smooth glass (which reflects or
    // transmits everything) and a white coated diffuse (the plastic BSDF, white to 0.003: its
    // albedo table's interpolation) vanish; pbrt's reflectance 1 becomes 0.999 (k finite); a
    // grey diffuse convex object is seen as its albedo, 0.5.
    for (material, expected, bias) in [
        ("\"diffuse\" \"rgb reflectance\" [1 1 1]", 1.0, 0.0),
        ("\"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]", 0.5, 0.0),
        ("\"dielectric\" \"float eta\" 1.5", 1.0, 0.0),
        ("\"conductor\" \"rgb reflectance\" [1 1 1]", 1.0, 0.0015),
        ("\"coateddiffuse\" \"rgb reflectance\" [1 1 1] \"float roughness\" 0.1", 1.0, 0.003),
        ("\"coateddiffuse\" \"rgb reflectance\" [1 1 1]", 1.0, 0.003),
    ] {
        let (mean, error) = pbrt_furnace(material);
        assert!(
            (mean - expected).abs() < 4.0 * error + bias + 1e-6,
            "{material}: {mean} ± {error}, expected {expected}"
        );
    }
    // Rough microfacet surfaces lose the light that would scatter between microfacets more than
    // once (single-scattering models): clearly below 1. At alpha 0.5 a white GGX conductor
    // reflects 0.688 of the light at normal incidence (quadrature of D G2 / (4 cos), height-
    // correlated Smith), more towards grazing angles, so the sphere's mean lies above 0.6.
    for material in [
        "\"conductor\" \"rgb reflectance\" [1 1 1] \"float roughness\" 0.25",
        "\"dielectric\" \"float eta\" 1.5 \"float roughness\" 0.09",
    ] {
        let (mean, error) = pbrt_furnace(material);
        assert!(mean < 1.0 - 4.0 * error && mean > 0.6, "{material}: {mean} ± {error}");
    }
    // A copper conductor is coloured: red above blue.
    let s = scene(
        "LookAt 0 0 4  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 20\nFilm \"rgb\" \"integer xresolution\" 4 \
         \"integer yresolution\" 4\nWorldBegin\nLightSource \"infinite\" \"rgb L\" [1 1 1]\nMaterial \"conductor\"\nShape \"sphere\"\n",
    );
    let centre = render(&s).film.get(2, 2);
    assert!(centre.x > 1.5 * centre.z, "copper {centre}");
}

#[test]
fn a_disk_light_gives_the_closed_form() {
    // A disk of radius R emitting Le downwards at height h over a diffuse plane of reflectance
    // rho: on its axis the irradiance is pi Le R^2 / (h^2 + R^2), the radiance rho Le R^2 /
    // (h^2 + R^2). The camera sees the point under the disk's centre from the side through a
    // tiny field of view, so all 64 pixels estimate that radiance independently; englobe draws
    // pbrt's disk as 128 triangles, whose inscribed polygon has (128 / 2pi) sin(2pi / 128) =
    // 0.9996 of the disk's area: a bias of 4e-4 at most, allowed for.
    let (le, r, h, rho) = (3.0, 0.5, 1.0, 0.7);
    let s = scene(&format!(
        "LookAt 3 0 0.5  0 0 0  0 0 1\nCamera \"perspective\" \"float fov\" 0.01\n\
         Film \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\n\
         Sampler \"independent\" \"integer pixelsamples\" 256\nIntegrator \"path\" \"integer maxdepth\" 3\n\
         WorldBegin\nAttributeBegin\nTranslate 0 0 {h}\nReverseOrientation\n\
         AreaLightSource \"diffuse\" \"rgb L\" [{le} {le} {le}]\nMaterial \"diffuse\" \"rgb reflectance\" [0 0 0]\n\
         Shape \"disk\" \"float radius\" {r}\nAttributeEnd\n\
         Material \"diffuse\" \"rgb reflectance\" [{rho} {rho} {rho}]\n\
         Shape \"trianglemesh\" \"point3 P\" [-50 -50 0 50 -50 0 50 50 0 -50 50 0] \"integer indices\" [0 1 2 0 2 3]\n"
    ));
    let values: Vec<f64> = render(&s).film.pixels().iter().map(|p| f64::from(p.x)).collect();
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let error = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
    let expected = rho * le * r * r / (h * h + r * r);
    assert!(error < 0.02 * expected, "the estimate is precise enough to test: {error}");
    assert!((mean - expected).abs() < 4.0 * error + 4e-4 * expected, "{mean} ± {error} against {expected}");
}

#[test]
fn a_point_light_inside_a_closed_diffuse_sphere_gives_rho_over_one_minus_rho() {
    // pbrt-v4's RadianceMatches: a point light of radiant intensity pi at the centre of a closed
    // diffuse sphere of radius 1 and albedo rho gives every wall the irradiance pi, so the
    // directly lit radiance rho; each further bounce multiplies it by rho (from a sphere's wall
    // every other wall is seen with the same form factor): rho / (1 - rho) in all.
    let rho = 0.6;
    let s = scene(&format!(
        "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\" \"float fov\" 90\n\
         Film \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\n\
         Sampler \"independent\" \"integer pixelsamples\" 128\nIntegrator \"path\" \"integer maxdepth\" 100\n\
         WorldBegin\nLightSource \"point\" \"rgb I\" [{pi} {pi} {pi}]\n\
         Material \"diffuse\" \"rgb reflectance\" [{rho} {rho} {rho}]\nShape \"sphere\" \"float radius\" 1\n",
        pi = PI
    ));
    let values: Vec<f64> = render(&s).film.pixels().iter().map(|p| f64::from(p.x)).collect();
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let error = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
    let expected = rho / (1.0 - rho);
    assert!(error < 0.02 * expected, "the estimate is precise enough to test: {error}");
    assert!((mean - expected).abs() < 4.0 * error, "{mean} ± {error} against {expected}");
}
