//! Batches allocate nothing per ray: a counting global allocator watches batches below the
//! parallel threshold, coherent (traced in packets) and not (nothing at all), and a large one (the thread pool's bookkeeping only, far
//! fewer allocations than rays). One test in this binary, so that no other test's allocations
//! are counted.

use englobe::accel::PARALLEL_BATCH;
use englobe::{AccelKind, Object, Ray, Sphere, TriangleMesh, Vec3, World};

#[path = "common/counting_alloc.rs"]
mod counting_alloc;

use counting_alloc::{all_allocations_during, allocations_during};

#[global_allocator]
static GLOBAL: counting_alloc::Counting = counting_alloc::Counting;

#[test]
fn batches_allocate_nothing_per_ray() {
    let (mut vertices, mut triangles) = (Vec::new(), Vec::new());
    for i in 0..40u32 {
        for j in 0..40u32 {
            let base = vertices.len() as u32;
            let o = [i as f32, j as f32, ((i * 7 + j * 3) % 5) as f32];
            vertices.extend([o, [o[0] + 1.0, o[1], o[2]], [o[0], o[1] + 1.0, o[2]]]);
            triangles.push([base, base + 1, base + 2]);
        }
    }
    let objects: Vec<Object> = vec![
        TriangleMesh::from_arrays(&vertices, &triangles).unwrap().into(),
        Sphere::new(Vec3::new(20.0, 20.0, 8.0), 3.0).into(),
    ];
    let world = World::build(objects, AccelKind::BvhWide).unwrap();
    let rays: Vec<Ray> = (0..100_000)
        .map(|k| {
            let f = k as f32;
            Ray::new(Vec3::new((f * 0.37) % 40.0, (f * 0.61) % 40.0, 12.0), Vec3::new(0.1, -0.05, -1.0))
        })
        .collect();
    // Coherent rays (a fan from one point), which batches trace in packets.
    let fan: Vec<Ray> = (0..PARALLEL_BATCH as u32 - 1)
        .map(|k| Ray::new(Vec3::new(20.0, 20.0, 30.0), Vec3::new((k % 32) as f32 * 0.01, (k / 32) as f32 * 0.01, -1.0)))
        .collect();
    let (mut hits, mut mask) = (vec![None; fan.len()], vec![false; fan.len()]);
    assert_eq!(allocations_during(|| world.closest_hits(&fan, &mut hits).unwrap()), 0);
    assert_eq!(allocations_during(|| world.any_hits(&fan, &mut mask).unwrap()), 0);
    assert!(hits.iter().filter(|h| h.is_some()).count() > fan.len() / 4);
    let small = &rays[..PARALLEL_BATCH - 1];
    let (mut hits, mut mask) = (vec![None; small.len()], vec![false; small.len()]);
    assert_eq!(allocations_during(|| world.closest_hits(small, &mut hits).unwrap()), 0);
    assert_eq!(allocations_during(|| world.any_hits(small, &mut mask).unwrap()), 0);
    assert!(hits.iter().filter(|h| h.is_some()).count() > small.len() / 4);
    let (mut hits, mut mask) = (vec![None; rays.len()], vec![false; rays.len()]);
    // The first parallel batch starts the thread pool.
    world.closest_hits(&rays, &mut hits).unwrap();
    let large = all_allocations_during(|| {
        world.closest_hits(&rays, &mut hits).unwrap();
        world.any_hits(&rays, &mut mask).unwrap();
    });
    assert!(large < rays.len() / 100, "{large} allocations for {} rays", 2 * rays.len());
}
