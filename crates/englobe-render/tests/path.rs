//! The path tracer against answers known in closed form.

use englobe::{AccelKind, Vec3};
use englobe_render::{RayKind, RenderOutput, Renderer, build_world};
use englobe_scene::{IntegratorKind, Scene, parse_scene};

fn scene(text: &str) -> Scene {
    parse_scene(text, "test.toml".as_ref()).unwrap_or_else(|e| panic!("{e}"))
}

fn render(scene: &Scene, integrator: IntegratorKind, threads: usize) -> RenderOutput {
    let world = build_world(scene, AccelKind::BvhSeedOrdered).unwrap();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| Renderer::new(scene, &world).integrator(integrator).count_work(true).render().unwrap())
}

#[test]
fn a_convex_diffuse_object_under_a_uniform_sky_reflects_albedo_times_sky() {
    // Every bounce from a convex object escapes to the sky, so each path gives exactly
    // albedo * sky: no noise at all, whatever the random numbers.
    let s = scene(
        r#"
[image]
width = 24
height = 24
samples = 3
max_depth = 5
background = [0.5, 1.0, 2.0]
[camera]
position = [0, 0, -4]
look_at = [0, 0, 0]
fov = 30
[materials.m]
diffuse = [0.5, 0.25, 0.125]
[[sphere]]
center = [0, 0, 0]
radius = 1
material = "m"
"#,
    );
    let out = render(&s, IntegratorKind::Path, 2);
    let on_object = Vec3::new(0.25, 0.25, 0.25);
    let (mut object, mut sky) = (0, 0);
    for &p in out.film.pixels() {
        if p == on_object {
            object += 1;
        } else if p == Vec3::new(0.5, 1.0, 2.0) {
            sky += 1;
        } else {
            // Pixels on the silhouette average sky and object samples.
            assert!(p.cmpge(on_object).all() && p.cmple(Vec3::new(0.5, 1.0, 2.0)).all(), "{p}");
        }
    }
    assert!(object > 100 && sky > 100, "{object} object pixels, {sky} sky pixels");
    assert!(out.stats.kind(RayKind::Bounce).rays > 0);
}

/// Twelve triangles making a closed cube around the camera, wound so that they face inward,
/// emitting `emission` and reflecting `albedo`; paths of at most `depth` bounces.
fn furnace(emission: f32, albedo: f32, depth: u32) -> String {
    let c = [[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]];
    // Quads listed counter-clockwise seen from inside the cube.
    let faces = [[0, 1, 2, 3], [5, 4, 7, 6], [4, 0, 3, 7], [1, 5, 6, 2], [4, 5, 1, 0], [3, 2, 6, 7]];
    let mut text = format!(
        "[image]\nwidth = 32\nheight = 32\nsamples = 24\nmax_depth = {depth}\n\
         [camera]\nposition = [0.1, 0.2, -0.3]\nlook_at = [0.3, -0.1, 1]\nfov = 100\n\
         [materials.wall]\ndiffuse = [{albedo}, {albedo}, {albedo}]\nemission = [{emission}, {emission}, {emission}]\n"
    );
    let v = |i: usize| format!("[{}, {}, {}]", c[i][0], c[i][1], c[i][2]);
    for f in faces {
        for tri in [[f[0], f[1], f[2]], [f[0], f[2], f[3]]] {
            text += &format!(
                "[[triangle]]\nvertices = [{}, {}, {}]\nmaterial = \"wall\"\n",
                v(tri[0]),
                v(tri[1]),
                v(tri[2])
            );
        }
    }
    text
}

#[test]
fn the_furnace_converges_to_emission_over_one_minus_albedo() {
    // Inside a closed box whose walls emit E and reflect a fraction a, the radiance everywhere
    // is E / (1 - a). Emitter sampling and bounces both find the walls, so this checks that their
    // multiple-importance weights add up to one, and that Russian roulette is unbiased.
    let s = scene(&furnace(0.1, 0.5, 64));
    let out = render(&s, IntegratorKind::Path, 2);
    let mean = out.film.pixels().iter().map(|p| p.x as f64).sum::<f64>() / out.film.pixels().len() as f64;
    // 24 576 paths; each is a sum of about two wall contributions: the standard error of the
    // mean is well under 0.5 %, so 2 % can only fail on a real bias.
    eprintln!("furnace mean {mean}");
    assert!((mean - 0.2).abs() < 0.2 * 0.02, "mean radiance {mean}, expected 0.2");
    assert!(out.stats.kind(RayKind::Shadow).rays > 0, "the walls were sampled as lights");
}

#[test]
fn with_only_direct_light_both_integrators_agree_exactly() {
    let s = scene(
        r#"
[image]
width = 40
height = 30
[camera]
position = [0, 1, -5]
look_at = [0, 0.5, 0]
[materials.m]
diffuse = [0.7, 0.5, 0.3]
specular = [0.4, 0.4, 0.4]
shininess = 30
[[point_light]]
position = [2, 4, -3]
intensity = 20
[[directional_light]]
direction = [-1, -1, 1]
intensity = 0.5
[[sphere]]
center = [0, 0.5, 0]
radius = 1
material = "m"
"#,
    );
    let whitted = render(&s, IntegratorKind::Whitted, 1);
    let path = render(&s, IntegratorKind::Path, 1);
    assert_eq!(whitted.film.pixels(), path.film.pixels());
}

#[test]
fn path_tracing_is_the_same_on_one_and_two_threads() {
    let s = scene(&furnace(0.2, 0.7, 64).replace("samples = 24", "samples = 2"));
    let one = render(&s, IntegratorKind::Path, 1);
    let two = render(&s, IntegratorKind::Path, 2);
    assert_eq!(one.film.pixels(), two.film.pixels());
    assert_eq!(one.stats, two.stats);
}

#[test]
fn the_depth_limited_furnace_sums_the_bounces_it_keeps() {
    // Seen through D bounces, the walls give Le (1 + rho + ... + rho^D) = Le (1 - rho^(D+1)) / (1 - rho).
    let (le, rho) = (0.1f32, 0.5f32);
    for depth in [0u32, 1, 2, 4] {
        let out = render(&scene(&furnace(le, rho, depth)), IntegratorKind::Path, 2);
        let got = out.film.pixels().iter().map(|p| p.x as f64).sum::<f64>() / out.film.pixels().len() as f64;
        let expected = le as f64 * (1.0 - (rho as f64).powi(depth as i32 + 1)) / (1.0 - rho as f64);
        // 24 576 paths whose value lies between Le and Le / (1 - rho): a standard error well under
        // 0.5 % of the mean; 2 % is several of them.
        assert!((got - expected).abs() < 0.02 * expected, "depth {depth}: {got} against {expected}");
    }
}
