//! Degenerate inputs for every structure of `AccelKind::ALL`: 100 000 primitives with one common
//! centre (identical spheres, 100 000 copies of one triangle, spheres nested by size, the worst
//! case of agglomerative clustering, and 70 000 triangles around one centroid), boxes of
//! zero volume (points and segments), and a completely flat mesh. Every one must build without a
//! panic, a stack overflow or a quadratic blow-up, give a valid tree with small leaves and a
//! bounded depth, and agree with brute force.

mod common;

use common::rng::{seeded, unit_vec3};
use common::{check_all_structures, load_obj};
use englobe::accel::bvh::validate_bvh;
use englobe::{Aabb, Accel, AccelKind, AnyAccel, Bounded, Intersect, Ray, Shape, Sphere, Triangle, TriangleMesh, Vec3};
use rand::seq::SliceRandom;

/// Most primitives per leaf of the SAH builders.
const MAX_LEAF: usize = 8;

/// Rays through the common centre from all around, along the axes and diagonals, and rays that
/// pass beside it.
fn rays_around(centre: Vec3, reach: f32) -> Vec<Ray> {
    let mut rays = Vec::new();
    for x in -1i32..=1 {
        for y in -1i32..=1 {
            for z in -1i32..=1 {
                let d = Vec3::new(x as f32, y as f32, z as f32);
                if d != Vec3::ZERO {
                    rays.push(Ray::new(centre - d * reach, d));
                    rays.push(Ray::new(centre + Vec3::new(0.3, -0.2, 0.1) * reach - d * reach, d));
                }
            }
        }
    }
    rays
}

/// Builds every structure over `boxes` and checks the shape of the BVHs: small leaves for the
/// builders that promise them, and a depth no greater than `max_depth`.
fn check_shape(boxes: &[Aabb], max_depth: u32) {
    for &kind in AccelKind::ALL {
        let accel = AnyAccel::build(kind, boxes);
        let Some(bvh) = accel.bvh() else { continue };
        let q = validate_bvh(bvh, boxes).unwrap_or_else(|e| panic!("{kind}: {e}"));
        assert!(q.depth <= max_depth, "{kind}: depth {} over {max_depth}", q.depth);
        if matches!(kind, AccelKind::BvhSah | AccelKind::BvhPloc | AccelKind::BvhSweep) {
            assert!(q.max_leaf <= MAX_LEAF, "{kind}: a leaf of {} primitives", q.max_leaf);
        }
    }
}

fn boxes_of(shapes: &[Shape]) -> Vec<Aabb> {
    shapes.iter().map(Bounded::bounds).collect()
}

#[test]
fn a_hundred_thousand_identical_spheres() {
    let shapes = vec![Shape::from(Sphere::new(Vec3::new(1.0, 2.0, 3.0), 0.5)); 100_000];
    let boxes = boxes_of(&shapes);
    // Split by count: log2(100 000 / 8) levels, about 14, for every builder.
    check_shape(&boxes, 24);
    let rays = rays_around(Vec3::new(1.0, 2.0, 3.0), 4.0);
    check_all_structures(&boxes, &rays, |i, r| shapes[i as usize].intersect(r)).unwrap();
}

#[test]
fn a_hundred_thousand_nested_spheres_with_one_centre() {
    // Radii growing with the index: every cluster's nearest neighbour is its smaller neighbour,
    // the case that stalls agglomerative clustering; also shuffled. The centres computed from the
    // boxes differ by rounding, so the SAH builders peel shells off; the trees get deeper than
    // for identical spheres (up to about 65 levels), never anywhere near one level per sphere.
    let centre = Vec3::new(-2.0, 0.5, 7.0);
    let mut shapes: Vec<Shape> = (0..100_000).map(|i| Sphere::new(centre, 0.01 + i as f32 * 1e-4).into()).collect();
    check_shape(&boxes_of(&shapes), 128);
    let rays = rays_around(centre, 30.0);
    check_all_structures(&boxes_of(&shapes), &rays, |i, r| shapes[i as usize].intersect(r)).unwrap();
    shapes.shuffle(&mut seeded(7));
    check_shape(&boxes_of(&shapes), 128);
}

#[test]
fn zero_volume_boxes() {
    // Triangles collapsed to points and to segments, and flat ones in axis planes: boxes with no
    // volume, some with no area. Degenerate triangles are never hit, but must be held.
    let mut shapes = Vec::new();
    for i in 0..3000 {
        let p = Vec3::new((i % 17) as f32, (i / 17 % 13) as f32, (i / 221) as f32) * 0.5;
        shapes.push(Shape::from(match i % 3 {
            0 => Triangle::new(p, p, p),
            1 => Triangle::new(p, p + Vec3::X * 0.4, p + Vec3::X * 0.2),
            _ => Triangle::new(p, p + Vec3::X * 0.4, p + Vec3::Y * 0.4),
        }));
    }
    let boxes = boxes_of(&shapes);
    check_shape(&boxes, 64);
    let mut rays = rays_around(Vec3::new(4.0, 3.0, 3.0), 20.0);
    for a in 0..12 {
        for b in 0..12 {
            let (x, y) = (a as f32 * 0.75, b as f32 * 0.5);
            // Down onto the grid, through points and segments, and along the grid's rows.
            rays.push(Ray::new(Vec3::new(x, y, 20.0), -Vec3::Z));
            rays.push(Ray::new(Vec3::new(-5.0, y, (b % 14) as f32 * 0.5), Vec3::X));
        }
    }
    check_all_structures(&boxes, &rays, |i, r| shapes[i as usize].intersect(r)).unwrap();
}

#[test]
fn a_flat_mesh() {
    // woody.obj lies entirely in the plane z = 0.
    let mesh = load_obj("scenes/meshes/small/woody.obj");
    let bounds = mesh.bounds();
    assert_eq!(bounds.min.z, bounds.max.z, "the mesh is flat");
    let boxes: Vec<Aabb> = (0..mesh.len() as u32).map(|t| mesh.triangle_bounds(t)).collect();
    check_shape(&boxes, 64);
    let (c, e) = (bounds.center(), bounds.extent());
    let mut rays = rays_around(c, e.length());
    for a in 0..16 {
        for b in 0..16 {
            let p = bounds.min + e * Vec3::new(a as f32 / 15.0, b as f32 / 15.0, 0.0);
            rays.push(Ray::new(p + Vec3::Z, -Vec3::Z));
            rays.push(Ray::new(p - Vec3::new(0.3, 0.2, 1.0), Vec3::new(0.3, 0.2, 1.0)));
            // In the mesh's plane: only edges lie in it, and nothing is hit.
            rays.push(Ray::new(Vec3::new(bounds.min.x - 1.0, p.y, c.z), Vec3::X));
        }
    }
    check_all_structures(&boxes, &rays, |i, r| mesh.intersect(i, r)).unwrap();
}

/// Builds every structure over `boxes` once (triangles clipped exactly with `clip`), bounds its
/// memory and depth, and checks it (validator, answers on `rays`) against brute force.
fn check_size_and_answers(
    boxes: &[Aabb],
    clip: englobe::accel::ClipFn<'_>,
    rays: &[Ray],
    intersect: impl Fn(u32, &Ray) -> Option<englobe::PrimHit> + Copy,
    max_depth: usize,
) {
    let expected = common::brute_force_answers(boxes, rays, intersect);
    for &kind in AccelKind::ALL {
        let accel = AnyAccel::build_with_clipper(kind, boxes, clip);
        let stats = accel.stats();
        // The grid's caps (64 references per primitive, 2^24 cells) bound it whatever the input;
        // the kd-tree references a primitive from every leaf it overlaps, and here every
        // primitive overlaps the centre (about 200 references each, bounded by the depth limit);
        // the BVHs are linear.
        let most = match kind {
            AccelKind::Grid => 64 * 4 * boxes.len() + (1 << 24) * 4 + 4096,
            AccelKind::KdTree => 1024 * boxes.len() + 4096,
            _ => 256 * boxes.len() + 4096,
        };
        assert!(stats.memory_bytes <= most, "{kind}: {} bytes for {} primitives", stats.memory_bytes, boxes.len());
        assert!(stats.depth <= max_depth, "{kind}: depth {}", stats.depth);
        common::check_structure(kind.name(), &accel, boxes, clip, rays, &expected, intersect).unwrap();
    }
}

#[test]
fn a_hundred_thousand_copies_of_one_triangle() {
    let (a, b, c) = (Vec3::new(1.0, 2.0, 3.0), Vec3::new(1.5, 2.0, 3.2), Vec3::new(1.2, 2.7, 2.9));
    let mesh = TriangleMesh::new(vec![a, b, c], vec![[0, 1, 2]; 100_000]).unwrap();
    let boxes: Vec<Aabb> = (0..mesh.len() as u32).map(|t| mesh.triangle_bounds(t)).collect();
    let clip = |t: u32, cell: &Aabb| englobe::shapes::clip_triangle(mesh.triangle(t).vertices, cell);
    let rays = rays_around((a + b + c) / 3.0, 4.0);
    check_size_and_answers(&boxes, &clip, &rays, |i, r| mesh.intersect(i, r), 64);
}

#[test]
fn seventy_thousand_triangles_with_one_centroid() {
    // Triangles of every size and orientation around one point, whose centroid is that point.
    let centre = Vec3::new(-2.0, 0.5, 7.0);
    let mut positions = Vec::new();
    let mut rng = seeded(0x2545_F491);
    for i in 0..70_000 {
        let scale = 0.01 + i as f32 * 1e-4;
        let u = (unit_vec3(&mut rng) - 0.5) * scale;
        let v = (unit_vec3(&mut rng) - 0.5) * scale;
        positions.extend([centre + u, centre + v, centre - u - v]);
    }
    let triangles = (0..70_000u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
    let mesh = TriangleMesh::new(positions, triangles).unwrap();
    let boxes: Vec<Aabb> = (0..mesh.len() as u32).map(|t| mesh.triangle_bounds(t)).collect();
    let clip = |t: u32, cell: &Aabb| englobe::shapes::clip_triangle(mesh.triangle(t).vertices, cell);
    let rays = rays_around(centre, 30.0);
    check_size_and_answers(&boxes, &clip, &rays, |i, r| mesh.intersect(i, r), 128);
}
