//! A crowd that moves every frame: thousands of instances of two meshes, each placed anew at every
//! frame with `World::move_instances` (the meshes' own structures are kept; only the structure
//! over the instances is built again), and a batch of rays traced after each update. Prints the
//! median time of an update and of the rays, and what the rays hit.
//!
//! `cargo run --release --example moving_instances [INSTANCES] [FRAMES]` (defaults 10000 and 20).

use std::sync::Arc;
use std::time::Instant;

use englobe::{AccelKind, Affine3A, Instance, Object, Ray, TriangleMesh, Vec3, World};

/// A sphere of `rings` x `2 rings` quads, radius 1, as a triangle mesh.
fn sphere(rings: u32) -> Arc<TriangleMesh> {
    let (n, m) = (rings, 2 * rings);
    let mut positions = Vec::new();
    for i in 0..=n {
        let theta = std::f32::consts::PI * i as f32 / n as f32;
        for j in 0..m {
            let phi = std::f32::consts::TAU * j as f32 / m as f32;
            positions.push(Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin()));
        }
    }
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let v = |i: u32, j: u32| i * m + j % m;
            // The pole rows are points: their degenerate triangles are skipped by the structure.
            triangles.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
            triangles.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    Arc::new(TriangleMesh::new(positions, triangles).expect("a valid sphere"))
}

/// Where instance `i` stands at `frame`: on a ring that turns, bobbing.
fn placement(i: usize, count: usize, frame: usize) -> Affine3A {
    let side = (count as f32).sqrt().ceil() as usize;
    let (x, z) = ((i % side) as f32 * 3.0, (i / side) as f32 * 3.0);
    let t = frame as f32 * 0.1 + i as f32 * 0.37;
    Affine3A::from_scale_rotation_translation(
        Vec3::splat(0.8 + 0.2 * t.sin()),
        glam::Quat::from_rotation_y(t),
        Vec3::new(x + t.cos(), (t * 1.3).sin(), z + t.sin()),
    )
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1).map(|a| a.parse::<usize>());
    let count = args.next().transpose()?.unwrap_or(10_000).max(1);
    let frames = args.next().transpose()?.unwrap_or(20).max(1);
    let meshes = [sphere(12), sphere(6)];
    let objects: Vec<Object> = (0..count)
        .map(|i| Instance::new(meshes[i % 2].clone(), placement(i, count, 0)).map(Object::from))
        .collect::<Result<_, _>>()?;
    let start = Instant::now();
    let mut world = World::build(objects, AccelKind::BvhWide)?;
    let build = start.elapsed().as_secs_f64() * 1e3;

    let b = world.bounds();
    let rays: Vec<Ray> = (0..10_000)
        .map(|k| {
            let (u, v) = ((k % 100) as f32 / 99.0, (k / 100) as f32 / 99.0);
            let target = Vec3::new(b.min.x + u * (b.max.x - b.min.x), 0.0, b.min.z + v * (b.max.z - b.min.z));
            let eye = Vec3::new(target.x * 0.5, b.max.y + 40.0, target.z * 0.5 - 20.0);
            Ray::new(eye, (target - eye).normalize())
        })
        .collect();
    let mut hits = vec![None; rays.len()];
    let (mut updates, mut traces) = (Vec::new(), Vec::new());
    let mut hit_counts = Vec::new();
    for frame in 1..=frames {
        let moves: Vec<(usize, Affine3A)> = (0..count).map(|i| (i, placement(i, count, frame))).collect();
        let t = Instant::now();
        world.move_instances(&moves)?;
        updates.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        world.closest_hits(&rays, &mut hits)?;
        traces.push(t.elapsed().as_secs_f64() * 1e3);
        hit_counts.push(hits.iter().filter(|h| h.is_some()).count());
    }
    println!(
        "{count} instances of 2 meshes ({} and {} triangles), built in {build:.1} ms",
        meshes[0].len(),
        meshes[1].len()
    );
    println!("every instance moved at each of {frames} frames: median update {:.2} ms", median(updates));
    println!(
        "{} rays after each update: median {:.2} ms; hits in the first and last frames: {} and {}",
        rays.len(),
        median(traces),
        hit_counts[0],
        hit_counts[hit_counts.len() - 1]
    );
    Ok(())
}
