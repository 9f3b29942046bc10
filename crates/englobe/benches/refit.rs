//! Refit against rebuild on the Stanford bunny whose every vertex moved by a small random offset:
//! the time of each, and the SAH cost of the refitted tree against a fresh build's (printed
//! before the timings). `cargo bench -p englobe --bench refit`.
//!
//! The bunny is read from the shared data folder (`ENGLOBE_SHARED`, or a `shared/` folder with
//! `scenes/` beside an ancestor of this crate), as the tests read it.

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};
use englobe::{TriangleBvh, Vec3};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg32;

fn shared_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("ENGLOBE_SHARED") {
        return PathBuf::from(dir);
    }
    let manifest = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    manifest
        .ancestors()
        .map(|a| a.join("shared"))
        .find(|s| s.join("scenes").is_dir())
        .expect("a shared/scenes folder beside an ancestor of the crate, or ENGLOBE_SHARED")
}

fn bunny() -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let path = shared_dir().join("scenes/meshes/bunny/stanford-bunny.obj");
    let (models, _) = tobj::load_obj(&path, &tobj::GPU_LOAD_OPTIONS).expect("the bunny");
    let (mut vertices, mut triangles) = (Vec::new(), Vec::new());
    for m in models {
        let base = vertices.len() as u32;
        vertices.extend(m.mesh.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        triangles.extend(m.mesh.indices.chunks_exact(3).map(|t| [base + t[0], base + t[1], base + t[2]]));
    }
    (vertices, triangles)
}

fn refit_vs_rebuild(c: &mut Criterion) {
    let (vertices, triangles) = bunny();
    let lo = vertices.iter().fold(Vec3::INFINITY, |m, &v| m.min(Vec3::from_array(v)));
    let hi = vertices.iter().fold(Vec3::NEG_INFINITY, |m, &v| m.max(Vec3::from_array(v)));
    let mut rng = Pcg32::seed_from_u64(0xb0_0bb1e5);
    let built = TriangleBvh::from_arrays(&vertices, &triangles).expect("a valid mesh");
    for fraction in [0.002f32, 0.01, 0.05] {
        let step = (hi - lo).length() * fraction;
        let moved: Vec<[f32; 3]> = vertices
            .iter()
            .map(|&v| {
                let o = Vec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - 1.0;
                (Vec3::from_array(v) + o * step).to_array()
            })
            .collect();
        let mut refitted = built.clone();
        let report = refitted.refit_arrays(&moved, &triangles).expect("the same mesh");
        let fresh = TriangleBvh::from_arrays(&moved, &triangles).expect("a valid mesh");
        println!(
            "bunny, {} triangles, every vertex moved up to {:.1} % of the diagonal per axis: SAH cost refitted {:.2}, \
             built before the move {:.2}, fresh build {:.2}; refitted / fresh = {:.3}{}",
            triangles.len(),
            fraction * 100.0,
            report.sah_cost,
            report.built_sah_cost,
            fresh.sah_cost(),
            report.sah_cost / fresh.sah_cost(),
            if report.rebuilt { " (rebuilt)" } else { "" },
        );
        let mut group = c.benchmark_group(format!("bunny moved {:.1} %", fraction * 100.0));
        group.sample_size(20);
        group.bench_function("refit", |b| {
            let mut bvh = built.clone();
            b.iter(|| black_box(bvh.refit_arrays(black_box(&moved), &triangles).unwrap()))
        });
        group.bench_function("rebuild", |b| {
            b.iter(|| black_box(TriangleBvh::from_arrays(black_box(&moved), &triangles).unwrap()))
        });
        group.finish();
    }
}

criterion_group!(benches, refit_vs_rebuild);
criterion_main!(benches);
