//! The claims of `docs/accelerators.md`, as counts (never times), on the scenes it measures,
//! rendered at a reduced size: the grid's sensitivity to differences of scale (a teapot in a
//! stadium against a uniformly filled cube), and the kd-tree's exact tests against the SAH BVH's on
//! the bunny and the Sponza. The scenes read meshes from the shared data folder, which must be
//! there (the test fails, loudly, without it).

use std::path::PathBuf;

use englobe::AccelKind;
use englobe_render::{Renderer, build_world};
use englobe_scene::load_scene;

/// The BVH the kd-tree and the grid are measured against.
const BVH: AccelKind = AccelKind::BvhSah;

/// Exact tests per ray of every structure of `kinds`, rendering `name` (under `scenes/`) at
/// `width` x `height`.
fn tests_per_ray(name: &str, width: u32, height: u32, kinds: &[AccelKind]) -> Vec<f64> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes").join(name);
    let scene = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
    kinds
        .iter()
        .map(|&kind| {
            let world = build_world(&scene, kind).unwrap();
            let out = Renderer::new(&scene, &world).size(width, height).count_work(true).render().unwrap();
            let total = out.stats.total();
            assert!(total.rays > 0);
            total.exact_tests as f64 / total.rays as f64
        })
        .collect()
}

#[test]
fn the_grid_is_sensitive_to_differences_of_scale() {
    let kinds = [BVH, AccelKind::Grid];
    let stadium = tests_per_ray("teapot-stadium.toml", 64, 48, &kinds);
    assert!(stadium[1] >= 10.0 * stadium[0], "teapot in a stadium: grid {} vs {BVH} {}", stadium[1], stadium[0]);
    let uniform = tests_per_ray("uniform-triangles.toml", 64, 48, &kinds);
    // Against the SAH BVH (not the seed BVH the bound was first set against) the grid makes about
    // 2.6 times its exact tests on the uniform cube: close, and far from the stadium's ratio.
    assert!(uniform[1] <= 3.0 * uniform[0], "uniform cube: grid {} vs {BVH} {}", uniform[1], uniform[0]);
    let (stadium_ratio, uniform_ratio) = (stadium[1] / stadium[0], uniform[1] / uniform[0]);
    assert!(stadium_ratio >= 4.0 * uniform_ratio, "grid/{BVH}: stadium {stadium_ratio}, uniform {uniform_ratio}");
}

#[test]
fn the_kdtree_tests_no_more_than_the_sah_bvh_on_the_bunny_and_the_sponza() {
    for name in ["bunny.toml", "sponza.toml"] {
        let t = tests_per_ray(name, 64, 48, &[BVH, AccelKind::KdTree]);
        assert!(t[1] <= t[0], "{name}: kdtree {} vs {BVH} {}", t[1], t[0]);
    }
}
