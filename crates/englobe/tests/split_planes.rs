//! Every structure of `AccelKind::ALL` against brute force where spatial subdivisions are
//! fragile: primitives lying in the planes that kd-trees split on and grid cells meet at, rays
//! lying in those planes or running along their edges, boxes sharing faces, everything at one
//! point, flat scenes, and a tiny detailed object in a huge sparse scene.

mod common;

use common::check_all_structures_clipped;
use englobe::shapes::clip_triangle;
use englobe::{AaBox, Aabb, Bounded, Intersect, Ray, Shape, Sphere, Triangle, Vec3};
use proptest::prelude::*;

fn check(shapes: &[Shape], rays: &[Ray]) {
    let boxes: Vec<Aabb> = shapes.iter().map(Bounded::bounds).collect();
    let clip = |i: u32, cell: &Aabb| match &shapes[i as usize] {
        Shape::Triangle(t) => clip_triangle(t.vertices, cell),
        s => s.bounds().intersection(cell),
    };
    check_all_structures_clipped(&boxes, &clip, rays, |i, r| shapes[i as usize].intersect(r)).unwrap();
}

/// The unit vector along `axis`, with the other components zeros of the given sign.
fn along(axis: usize, sign: f32, negative_zeros: bool) -> Vec3 {
    let mut d = Vec3::splat(if negative_zeros { -0.0 } else { 0.0 });
    d[axis] = sign;
    d
}

/// Two triangles per unit square of the integer lattice in the plane `axis = level`, over
/// `[-n, n)` in the other two axes.
fn flat_squares(axis: usize, level: f32, n: i32) -> Vec<Shape> {
    let mut out = Vec::new();
    let point = |a: i32, b: i32| {
        let mut p = Vec3::ZERO;
        p[axis] = level;
        p[(axis + 1) % 3] = a as f32;
        p[(axis + 2) % 3] = b as f32;
        p
    };
    for a in -n..n {
        for b in -n..n {
            out.push(Triangle::new(point(a, b), point(a + 1, b), point(a + 1, b + 1)).into());
            out.push(Triangle::new(point(a, b), point(a + 1, b + 1), point(a, b + 1)).into());
        }
    }
    out
}

/// Rays that lie in the lattice's planes `axis = k` and run along its lines, plus rays across
/// them through lattice points, all starting on integer or half-integer coordinates.
fn lattice_rays(n: i32) -> Vec<Ray> {
    let mut rays = Vec::new();
    for axis in 0..3 {
        for k in -n..=n {
            for j in -n..=n {
                for (sign, zeros) in [(1.0, false), (-1.0, true)] {
                    let d = along(axis, sign, zeros);
                    // Along a lattice line: every plane it lies in holds flat primitives.
                    let mut o = Vec3::splat(k as f32);
                    o[(axis + 1) % 3] = j as f32;
                    o[axis] = -sign * (n as f32 + 2.0);
                    rays.push(Ray::new(o, d));
                    // In a plane, between lines.
                    o[(axis + 2) % 3] = k as f32 + 0.5;
                    rays.push(Ray::new(o, d));
                    // Diagonally in the plane `axis = k`.
                    let mut diag = Vec3::ZERO;
                    diag[(axis + 1) % 3] = 1.0;
                    diag[(axis + 2) % 3] = sign;
                    let mut o = Vec3::splat(-(n as f32) - 2.0);
                    o[axis] = k as f32;
                    o[(axis + 2) % 3] = j as f32 * sign;
                    rays.push(Ray::new(o, diag));
                }
            }
        }
    }
    // Across the planes, through lattice points and cell centres, and from inside.
    for i in -n..=n {
        for j in -n..=n {
            let p = Vec3::new(i as f32, j as f32, (i + j) as f32 * 0.5);
            rays.push(Ray::new(p - Vec3::new(3.0, 2.0, 1.0) * 7.0, Vec3::new(3.0, 2.0, 1.0)));
            rays.push(Ray::new(p, Vec3::new(-1.0, 1.0, 1.0)));
            rays.push(Ray::segment(p, Vec3::new(1.0, 0.0, 1.0), 0.0, 1.0));
        }
    }
    rays
}

#[test]
fn flat_triangles_in_three_families_of_axis_planes() {
    // Squares in the planes x = -1, 0, 1, y = 0 and z = 2: the planes kd-trees split on.
    let mut shapes = Vec::new();
    for level in [-1.0, 0.0, 1.0] {
        shapes.extend(flat_squares(0, level, 2));
    }
    shapes.extend(flat_squares(1, 0.0, 2));
    shapes.extend(flat_squares(2, 2.0, 2));
    check(&shapes, &lattice_rays(3));
}

#[test]
fn boxes_sharing_faces_edges_and_corners() {
    // A 4x4x4 block of unit boxes, every other one missing, so rays slip along shared faces.
    let mut shapes: Vec<Shape> = Vec::new();
    for x in -2..2 {
        for y in -2..2 {
            for z in -2..2 {
                if (x + y + z) % 2 == 0 {
                    let p = Vec3::new(x as f32, y as f32, z as f32);
                    shapes.push(AaBox::new(p, p + Vec3::ONE).into());
                }
            }
        }
    }
    check(&shapes, &lattice_rays(3));
}

#[test]
fn everything_at_one_point() {
    // Spheres of no visible size and triangles shrunk to a point, all at (1, 1, 1): one cell,
    // one leaf, and every ray through the point ties.
    let mut shapes: Vec<Shape> = (0..20).map(|_| Sphere::new(Vec3::ONE, 1e-3).into()).collect();
    shapes.extend((0..20).map(|i| {
        let e = 1e-4 * (i + 1) as f32;
        Shape::from(Triangle::new(Vec3::ONE - Vec3::X * e, Vec3::ONE + Vec3::Y * e, Vec3::ONE + Vec3::Z * e))
    }));
    let mut rays = lattice_rays(2);
    for d in [Vec3::X, -Vec3::Y, Vec3::ONE, Vec3::new(-1.0, 2.0, 0.5)] {
        rays.push(Ray::new(Vec3::ONE - d * 5.0, d));
        rays.push(Ray::new(Vec3::ONE, d));
    }
    check(&shapes, &rays);
}

#[test]
fn a_tiny_detailed_object_in_a_huge_sparse_scene() {
    // A floor and four walls 2000 units across, and a fine mesh of 20 000 triangles 2 units
    // across in the middle: the grid's weak case, still exact.
    let mut shapes: Vec<Shape> = Vec::new();
    let big = 1000.0;
    for (a, b, c) in [
        (Vec3::new(-big, 0.0, -big), Vec3::new(big, 0.0, -big), Vec3::new(big, 0.0, big)),
        (Vec3::new(-big, 0.0, -big), Vec3::new(big, 0.0, big), Vec3::new(-big, 0.0, big)),
    ] {
        shapes.push(Triangle::new(a, b, c).into());
    }
    for (min, max) in [
        (Vec3::new(-big, 0.0, -big), Vec3::new(-big + 10.0, 50.0, big)),
        (Vec3::new(big - 10.0, 0.0, -big), Vec3::new(big, 50.0, big)),
        (Vec3::new(-big, 0.0, -big), Vec3::new(big, 50.0, -big + 10.0)),
        (Vec3::new(-big, 0.0, big - 10.0), Vec3::new(big, 50.0, big)),
    ] {
        shapes.push(AaBox::new(min, max).into());
    }
    let n = 100;
    for i in 0..n {
        for j in 0..n {
            let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
            let s = 1.0 / n as f32;
            let p = |u: f32, v: f32| {
                let (a, b) = (u * std::f32::consts::TAU, v * std::f32::consts::PI);
                Vec3::new(b.sin() * a.cos(), 1.0 + b.cos(), b.sin() * a.sin())
            };
            shapes.push(Triangle::new(p(u, v), p(u + s, v), p(u + s, v + s)).into());
            shapes.push(Triangle::new(p(u, v), p(u + s, v + s), p(u, v + s)).into());
        }
    }
    let mut rays = Vec::new();
    let eye = Vec3::new(1.5, 1.8, 3.0);
    for i in 0..40 {
        for j in 0..30 {
            let d = Vec3::new(i as f32 / 20.0 - 1.0, j as f32 / 15.0 - 1.0, -1.5);
            rays.push(Ray::new(eye, d));
        }
    }
    // Axis-parallel rays from the far walls and from the mesh's centre. (Not through the mesh's
    // poles, where dozens of triangles meet at one vertex and their hit distances differ in the
    // last bits: there the closest is a matter of rounding, which not every structure settles
    // like brute force.)
    let off = Vec3::new(0.013, 1.007, 0.011);
    for axis in 0..3 {
        rays.push(Ray::new(off + along(axis, -900.0, false), along(axis, 1.0, false)));
        rays.push(Ray::new(off, along(axis, -1.0, true)));
    }
    check(&shapes, &rays);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// Random triangles lying in one plane `z = 0` (a flat scene: a flat grid, a kd-tree whose
    /// root cell has no height) and random rays, many of them in that plane.
    #[test]
    fn a_flat_scene(
        tris in prop::collection::vec(
            ((-8i32..8, -8i32..8), (-3i32..=3, -3i32..=3), (-3i32..=3, -3i32..=3)), 1..80),
        rays in prop::collection::vec(((-10i32..10, -10i32..10, -2i32..=2), (-3i32..=3, -3i32..=3, -1i32..=1)), 1..40),
    ) {
        let shapes: Vec<Shape> = tris
            .iter()
            .map(|&((x, y), (ax, ay), (bx, by))| {
                let p = Vec3::new(x as f32, y as f32, 0.0);
                Triangle::new(p, p + Vec3::new(ax as f32, ay as f32, 0.0) * 0.5, p + Vec3::new(bx as f32, by as f32, 0.0) * 0.5).into()
            })
            .collect();
        let rays: Vec<Ray> = rays
            .iter()
            .filter(|(_, d)| *d != (0, 0, 0))
            .map(|&((x, y, z), (dx, dy, dz))| {
                Ray::new(Vec3::new(x as f32 * 0.5, y as f32 * 0.5, z as f32 * 0.5), Vec3::new(dx as f32, dy as f32, dz as f32))
            })
            .collect();
        check(&shapes, &rays);
    }

    /// Axis-aligned flat triangles on integer planes of all three axes, with rays on integer and
    /// half-integer coordinates along the axes and the diagonals of the planes.
    #[test]
    fn random_axis_aligned_flat_triangles(
        tris in prop::collection::vec((0usize..3, (-4i32..4, -4i32..4, -4i32..4), 1i32..3, 1i32..3), 1..60),
        rays in prop::collection::vec(((-8i32..8, -8i32..8, -8i32..8), 0usize..9), 1..40),
    ) {
        let shapes: Vec<Shape> = tris
            .iter()
            .map(|&(axis, (x, y, z), a, b)| {
                let p = Vec3::new(x as f32, y as f32, z as f32);
                let (mut u, mut v) = (Vec3::ZERO, Vec3::ZERO);
                u[(axis + 1) % 3] = a as f32;
                v[(axis + 2) % 3] = b as f32;
                Triangle::new(p, p + u, p + v).into()
            })
            .collect();
        let directions = [
            Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z,
            Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, -1.0, 1.0), Vec3::new(1.0, 0.0, -1.0),
        ];
        let rays: Vec<Ray> = rays
            .iter()
            .map(|&((x, y, z), d)| Ray::new(Vec3::new(x as f32, y as f32, z as f32) * 0.5, directions[d]))
            .collect();
        check(&shapes, &rays);
    }
}
