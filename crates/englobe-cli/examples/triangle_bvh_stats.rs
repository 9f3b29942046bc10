//! The triangle fast path on mesh files: references (each piece of a cut triangle counts one),
//! build time (median of five builds, in triangles per second), wide nodes, leaves, triangles per
//! leaf and per block, bytes, and the work of random rays, closest and any hit (wide nodes visited
//! and triangles tested per ray). Where `docs/performance.md`'s structure
//! figures come from:
//!
//! ```sh
//! cargo run --release -p englobe-cli --example triangle_bvh_stats -- \
//!     ../shared/scenes/meshes/bunny/stanford-bunny.obj ../shared/scenes/meshes/ogre/ogre.obj \
//!     ../shared/scenes/meshes/sponza-dabrovic/sponza.obj
//! ```
//!
//! `--presplit PERCENT` first builds with that pre-split budget instead of the library's default;
//! `--spatial LEVELS` (after it, if both) with spatial splits in that many top levels instead.
//! The SAH cost is given in the units of Embree's own report, to set beside it (see
//! `docs/performance.md`).

use std::path::Path;
use std::time::Instant;

use anyhow::Context;
use englobe::accel::wide::triangle_bvh::TriangleBvhOptions;
use englobe::{Ray, TriangleBvh, Vec3, WorkCounts};
use englobe_scene::mesh::load_mesh_file;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg32;

fn main() -> anyhow::Result<()> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut options = TriangleBvhOptions::default();
    if args.first().is_some_and(|a| a == "--presplit") {
        let percent = args.get(1).context("--presplit needs a percentage")?;
        options.presplit_percent = percent.parse().with_context(|| format!("--presplit {percent}"))?;
        args.drain(..2);
    }
    if args.first().is_some_and(|a| a == "--spatial") {
        let levels = args.get(1).context("--spatial needs a number of levels")?;
        options.spatial_levels = levels.parse().with_context(|| format!("--spatial {levels}"))?;
        args.drain(..2);
    }
    for path in args {
        let loaded = load_mesh_file(Path::new(&path)).with_context(|| path.clone())?;
        let mesh = loaded.mesh;
        let mut times = Vec::new();
        let mut bvh = None;
        for _ in 0..5 {
            let start = Instant::now();
            bvh = Some(TriangleBvh::build_with(mesh.len(), |i| mesh.triangle(i).vertices, options));
            times.push(start.elapsed().as_secs_f64());
        }
        times.sort_by(f64::total_cmp);
        let bvh = bvh.expect("built");
        let s = bvh.stats();
        let blocks = bvh.blocks().len();
        let stored = s.prim_refs;
        println!(
            "{path}: {} triangles, {stored} references ({:.3} per triangle); build {:.1} ms ({:.1} M triangles/s); \
             {} wide nodes, {} leaves, depth {}; {:.2} triangles per leaf, {:.2} per block ({blocks} blocks); {:.1} MiB",
            mesh.len(),
            stored as f64 / mesh.len() as f64,
            times[2] * 1e3,
            mesh.len() as f64 / times[2] / 1e6,
            s.nodes,
            s.leaves,
            s.depth,
            stored as f64 / s.leaves as f64,
            stored as f64 / blocks as f64,
            s.memory_bytes as f64 / (1 << 20) as f64
        );
        let (nodes, leaves) = embree_sah(&bvh);
        println!("  SAH cost in Embree's units: {:.3} (nodes {nodes:.3}, leaves {leaves:.3})", nodes + leaves);
        // Random rays: uniform origins in the box, uniform directions (the harness's random set).
        let (lo, extent) = (mesh.bounds().min, mesh.bounds().extent());
        let mut rng = Pcg32::seed_from_u64(0x9e37_79b9_7f4a_7c15);
        let mut next = move || (rng.next_u32() >> 8) as f32 / (1u32 << 24) as f32;
        let rays: Vec<Ray> = (0..100_000)
            .map(|_| {
                let o = lo + extent * Vec3::new(next(), next(), next());
                Ray::new(o, Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5))
            })
            .collect();
        let n = rays.len() as f64;
        let report = |query: &str, hit: &dyn Fn(&Ray, &mut WorkCounts) -> bool| {
            let mut c = WorkCounts::default();
            let hits = rays.iter().filter(|ray| hit(ray, &mut c)).count();
            println!(
                "  {query}: {:.2} wide nodes and {:.2} triangles tested per ray ({:.1} % hit)",
                c.nodes_visited as f64 / n,
                c.exact_tests as f64 / n,
                100.0 * hits as f64 / n
            );
        };
        report("random rays, closest hit", &|ray, c| bvh.closest_hit(ray, c).is_some());
        report("the same rays, any hit", &|ray, c| bvh.any_hit(ray, c));
    }
    Ok(())
}

/// The tree's SAH cost as Embree's builders report it (its device's `verbose=3`): every wide node
/// costs its box's area, every leaf its box's area per block of four triangles, relative to the
/// root's box; returned as the nodes' part and the leaves' part.
fn embree_sah(bvh: &TriangleBvh) -> (f64, f64) {
    use englobe::accel::wide::node::{EMPTY, WIDTH, is_leaf};
    let root = bvh.bounds().surface_area() as f64;
    // A node's box is the one its parent holds for it; the root's is the tree's.
    let mut area = vec![0.0; bvh.nodes().len()];
    area[0] = root;
    let (mut nodes, mut leaves) = (0.0, 0.0);
    for (i, node) in bvh.nodes().iter().enumerate() {
        nodes += area[i] / root;
        for slot in (0..WIDTH).filter(|&s| node.children[s] != EMPTY) {
            let a = node.child_bounds(slot).surface_area() as f64;
            if is_leaf(node.children[slot]) {
                leaves += a / root * node.counts[slot] as f64;
            } else {
                area[node.children[slot] as usize] = a;
            }
        }
    }
    (nodes, leaves)
}
