//! The BVH builders and their settings side by side on mesh files: SAH cost (with the constants of
//! `englobe::accel::bvh::stats`), its ratio to the full sweep's, build time (median of five
//! builds), interior nodes, leaves and depth. Every tree is validated. This is where the figures
//! of `docs/bvh.md` on bin counts, PLOC's search radius and its restructuring passes come from:
//!
//! ```sh
//! cargo run --release -p englobe-cli --example bvh_builders -- \
//!     ../shared/scenes/meshes/bunny/stanford-bunny.obj \
//!     ../shared/scenes/meshes/sponza-dabrovic/sponza.obj \
//!     ../shared/scenes/meshes/dragon-lowres/dragon_lowres_22k.ply
//! ```

use std::path::Path;
use std::time::Instant;

use anyhow::Context;
use englobe::Aabb;
use englobe::accel::Bvh;
use englobe::accel::bvh::validate_bvh;
use englobe::accel::{BinnedSah, Ploc, SeedPairing, SweepSah};
use englobe_scene::mesh::load_mesh_file;

/// A builder with its settings, ready to run on boxes.
type Builder = Box<dyn Fn(&[Aabb]) -> Bvh>;

/// One builder with its settings.
struct Variant {
    name: String,
    build: Builder,
}

fn variants() -> Vec<Variant> {
    let mut v = vec![Variant { name: "seed pairing".into(), build: Box::new(SeedPairing::build) }];
    for bins in [8, 16, 32] {
        let builder = BinnedSah { bins, ..BinnedSah::default() };
        v.push(Variant { name: format!("binned SAH, {bins} bins"), build: Box::new(move |b| builder.build(b)) });
    }
    v.push(Variant { name: "full-sweep SAH".into(), build: Box::new(|b| SweepSah::default().build(b)) });
    for radius in [8, 16] {
        for passes in [0, 1, 2] {
            let builder = Ploc { radius, restructure_passes: passes, ..Ploc::default() };
            v.push(Variant {
                name: format!("PLOC, radius {radius}, {passes} passes"),
                build: Box::new(move |b| builder.build(b)),
            });
        }
    }
    v
}

fn main() -> anyhow::Result<()> {
    let files: Vec<String> = std::env::args().skip(1).collect();
    anyhow::ensure!(!files.is_empty(), "usage: bvh_builders MESH...");
    let variants = variants();
    for file in files {
        let loaded = load_mesh_file(Path::new(&file)).with_context(|| format!("cannot load {file}"))?;
        let mesh = loaded.mesh;
        let boxes: Vec<Aabb> = (0..mesh.len() as u32).map(|t| mesh.triangle_bounds(t)).collect();
        println!("{file}: {} triangles", boxes.len());
        println!(
            "  {:<30} {:>10} {:>9} {:>10} {:>9} {:>9} {:>6}",
            "builder", "SAH cost", "vs sweep", "build ms", "interior", "leaves", "depth"
        );
        let sweep = SweepSah::default().build(&boxes).sah_cost();
        for v in &variants {
            let mut times = Vec::new();
            let mut bvh = Bvh::empty();
            for _ in 0..5 {
                let start = Instant::now();
                bvh = (v.build)(&boxes);
                times.push(start.elapsed().as_secs_f64());
            }
            times.sort_by(f64::total_cmp);
            let q = validate_bvh(&bvh, &boxes).with_context(|| format!("{}: invalid tree", v.name))?;
            println!(
                "  {:<30} {:>10.3} {:>9.3} {:>10.1} {:>9} {:>9} {:>6}",
                v.name,
                q.sah_cost,
                q.sah_cost / sweep,
                times[2] * 1e3,
                q.interior,
                q.leaves,
                q.depth
            );
        }
    }
    Ok(())
}
