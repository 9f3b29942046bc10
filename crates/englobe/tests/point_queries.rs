//! Point and box queries of [`TriangleBvh`] and [`World`] against brute force: the closest point
//! within a radius (Ericson's closest point on each triangle, ties to the lower index) and the
//! triangles overlapping a box (Akenine-Möller's separating axis test), bit for bit, on random
//! soups with degenerate triangles, on ties between copies, and on the Stanford bunny.

mod common;

use common::load_obj;
use common::rng::{in_box, seeded};
use common::strategies::{point, triangle};
use englobe::shapes::{closest_point_on_triangle, distance_squared, is_degenerate, triangle_overlaps_box};
use englobe::{Aabb, AccelKind, ClosestPoint, Object, TriangleBvh, TriangleMesh, Vec3, World};
use proptest::prelude::*;

/// The closest point by testing every triangle the structure stores (zero-area ones are not).
fn brute_closest(tris: &[[Vec3; 3]], p: Vec3, radius: f32) -> Option<ClosestPoint> {
    let mut best: Option<(f32, ClosestPoint)> = None;
    let limit = radius * radius;
    for (i, t) in tris.iter().enumerate() {
        if is_degenerate(t[0], t[1], t[2]) {
            continue;
        }
        let q = closest_point_on_triangle(p, *t);
        let d2 = distance_squared(p, q);
        if best.map_or(d2 <= limit, |(b, _)| d2 < b) {
            best = Some((d2, ClosestPoint { prim: i as u32, point: q, distance: d2.sqrt() }));
        }
    }
    best.map(|(_, c)| c)
}

fn brute_in_box(tris: &[[Vec3; 3]], query: &Aabb) -> Vec<u32> {
    (0..tris.len() as u32)
        .filter(|&i| {
            let t = tris[i as usize];
            !is_degenerate(t[0], t[1], t[2]) && triangle_overlaps_box(t, query)
        })
        .collect()
}

/// Checks both queries; returns (points found, triangles found in boxes).
fn check(tris: &[[Vec3; 3]], points: &[(Vec3, f32)], boxes: &[Aabb]) -> Result<(usize, usize), String> {
    let bvh = TriangleBvh::from_triangles(tris);
    let mut found = (0, 0);
    for &(p, r) in points {
        let expected = brute_closest(tris, p, r);
        let got = bvh.closest_point(p, r);
        if got != expected {
            return Err(format!("closest point to {p} within {r}: brute force {expected:?}, TriangleBvh {got:?}"));
        }
        found.0 += expected.is_some() as usize;
    }
    for b in boxes {
        let expected = brute_in_box(tris, b);
        let got = bvh.triangles_in_box(b);
        if got != expected {
            return Err(format!("triangles in {b:?}: brute force {expected:?}, TriangleBvh {got:?}"));
        }
        found.1 += expected.len();
    }
    Ok(found)
}

/// Points anywhere (some on the grid of integer vertices), with a radius or none.
fn query_point() -> impl Strategy<Value = (Vec3, f32)> {
    let radius = prop_oneof![1 => Just(f32::INFINITY), 2 => 0.0f32..2.0, 1 => Just(0.0f32)];
    (point().prop_map(|p| p * 1.5), radius)
}

fn query_box() -> impl Strategy<Value = Aabb> {
    let half = prop_oneof![3 => (0.0f32..1.5, 0.0f32..1.5, 0.0f32..1.5), 1 => Just((0.0, 0.0, 0.0))];
    (point(), half).prop_map(|(c, (x, y, z))| {
        let h = Vec3::new(x, y, z);
        Aabb::new(c - h, c + h)
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn random_soups_agree_with_brute_force(
        tris in prop::collection::vec(triangle(), 1..400),
        points in prop::collection::vec(query_point(), 1..40),
        boxes in prop::collection::vec(query_box(), 1..20),
    ) {
        check(&tris, &points, &boxes).map_err(TestCaseError::fail)?;
    }
}

#[test]
fn copies_tie_to_the_lower_index() {
    // Every triangle three times.
    let mut tris = Vec::new();
    for i in 0..600 {
        let x = (i % 25) as f32 * 0.8;
        let y = (i / 25) as f32 * 0.8;
        let t = [Vec3::new(x, y, 0.0), Vec3::new(x + 0.5, y, 0.0), Vec3::new(x, y + 0.5, 0.2)];
        tris.extend([t, t, t]);
    }
    let mut rng = seeded(0x51de_c0de);
    let bounds = Aabb::from_points(tris.iter().flatten().copied());
    let points: Vec<(Vec3, f32)> = (0..300).map(|i| (in_box(&mut rng, &bounds), [f32::INFINITY, 0.2][i % 2])).collect();
    let boxes: Vec<Aabb> = (0..100)
        .map(|_| {
            let c = in_box(&mut rng, &bounds);
            Aabb::new(c - Vec3::splat(0.5), c + Vec3::splat(0.5))
        })
        .collect();
    let (near, inside) = check(&tris, &points, &boxes).unwrap();
    assert!(near > 150 && inside > 300, "{near} points, {inside} triangles in boxes");
    let bvh = TriangleBvh::from_triangles(&tris);
    for (p, r) in points {
        if let Some(c) = bvh.closest_point(p, r) {
            assert_eq!(c.prim % 3, 0, "the first of three copies");
        }
    }
}

#[test]
fn deep_trees_of_nested_triangles() {
    // Nested triangles shrinking geometrically around one point: the SAH separates them a few at
    // a time, so the tree is deep, and points near the centre walk down much of it.
    let tris: Vec<[Vec3; 3]> = (0..4000)
        .map(|i| {
            let s = 0.99f32.powi(i);
            [Vec3::new(-s, -s, s * 0.1), Vec3::new(s, -s, s * 0.1), Vec3::new(0.0, s, s * 0.1)]
        })
        .collect();
    assert!(TriangleBvh::from_triangles(&tris).depth() > 16);
    let mut rng = seeded(0xdee9);
    let unit = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
    let points: Vec<(Vec3, f32)> =
        (0..200).map(|i| (in_box(&mut rng, &unit) * 0.1, [f32::INFINITY, 0.01][i % 2])).collect();
    let boxes: Vec<Aabb> = (0..50)
        .map(|_| {
            let c = in_box(&mut rng, &unit) * 0.2;
            Aabb::new(c, c + Vec3::splat(0.01))
        })
        .collect();
    let (near, inside) = check(&tris, &points, &boxes).unwrap();
    assert!(near > 100 && inside > 0, "{near} points, {inside} triangles in boxes");
}

#[test]
fn stanford_bunny_agrees_with_brute_force() {
    let mesh = load_obj("scenes/meshes/bunny/stanford-bunny.obj");
    let tris: Vec<[Vec3; 3]> = (0..mesh.len() as u32).map(|i| mesh.triangle(i).vertices).collect();
    let bounds = mesh.bounds();
    let grown = Aabb::new(bounds.min - bounds.extent() * 0.5, bounds.max + bounds.extent() * 0.5);
    let mut rng = seeded(0xb0b5_1ed0);
    let scale = bounds.extent().length();
    let points: Vec<(Vec3, f32)> =
        (0..400).map(|i| (in_box(&mut rng, &grown), [f32::INFINITY, 0.05 * scale][i % 2])).collect();
    let boxes: Vec<Aabb> = (0..60)
        .map(|_| {
            let c = in_box(&mut rng, &bounds);
            Aabb::new(c - bounds.extent() * 0.04, c + bounds.extent() * 0.04)
        })
        .collect();
    let (near, inside) = check(&tris, &points, &boxes).unwrap();
    assert!(near > 200 && inside > 500, "{near} points, {inside} triangles in boxes");
}

#[test]
fn worlds_answer_for_their_meshes_whatever_the_structure() {
    let mut rng = seeded(0x03a1_13e5);
    let mut mesh = |offset: Vec3| {
        let vertices: Vec<[f32; 3]> =
            (0..60).map(|_| (in_box(&mut rng, &Aabb::new(Vec3::ZERO, Vec3::ONE)) + offset).to_array()).collect();
        let triangles: Vec<[u32; 3]> = (0..40u32).map(|i| [i, i + 7, i + 19]).collect();
        TriangleMesh::from_arrays(&vertices, &triangles).unwrap()
    };
    let objects: Vec<Object> = vec![
        englobe::Sphere::new(Vec3::new(5.0, 5.0, 5.0), 1.0).into(),
        mesh(Vec3::ZERO).into(),
        mesh(Vec3::new(0.5, 0.0, 0.0)).into(),
    ];
    let fast = World::build(objects.clone(), AccelKind::BvhWide).unwrap();
    let slow = World::build(objects, AccelKind::KdTree).unwrap();
    let (mut near, mut inside) = (0, 0);
    for i in 0..500 {
        let p = in_box(&mut rng, &Aabb::new(Vec3::splat(-1.0), Vec3::splat(2.5)));
        let r = [f32::INFINITY, 0.3][i % 2];
        let a = fast.closest_point(p, r);
        assert_eq!(a, slow.closest_point(p, r), "{p} within {r}");
        near += a.is_some() as usize;
        if let Some(a) = a {
            assert!(a.object == 1 || a.object == 2);
        }
        let b = Aabb::new(p - Vec3::splat(0.1), p + Vec3::splat(0.1));
        let got = fast.triangles_in_box(&b);
        assert_eq!(got, slow.triangles_in_box(&b), "{b:?}");
        inside += got.len();
    }
    assert!(near > 250 && inside > 60, "{near} points, {inside} triangles in boxes");
}

#[test]
fn flat_arrays_build_what_arrays_of_triples_build() {
    let mesh = load_obj("scenes/meshes/bunny/stanford-bunny.obj");
    let flat_vertices: Vec<f32> = mesh.positions().iter().flat_map(|p| p.to_array()).collect();
    let flat_indices: Vec<u32> = mesh.triangles().iter().flatten().copied().collect();
    let triples: Vec<[f32; 3]> = mesh.positions().iter().map(|p| p.to_array()).collect();
    let from_flat = TriangleBvh::from_flat(&flat_vertices, &flat_indices).unwrap();
    let from_arrays = TriangleBvh::from_arrays(&triples, mesh.triangles()).unwrap();
    assert_eq!(from_flat.nodes(), from_arrays.nodes());
    assert_eq!(from_flat.blocks(), from_arrays.blocks());
    assert_eq!(TriangleMesh::from_flat(&flat_vertices, &flat_indices).unwrap().triangles(), mesh.triangles());
    let e = TriangleBvh::from_flat(&flat_vertices[1..], &flat_indices).unwrap_err();
    assert_eq!(e.to_string(), format!("vertices has {} numbers, not a multiple of 3", flat_vertices.len() - 1));
    let e = TriangleMesh::from_flat(&flat_vertices, &flat_indices[..4]).unwrap_err();
    assert_eq!(e.to_string(), "indices has 4 numbers, not a multiple of 3");
}
