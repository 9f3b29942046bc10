//! Every structure of `AccelKind::ALL` against brute force: the same closest hit (primitive and
//! `t`) and the same any-hit answer, on random scenes of spheres and triangles and random rays
//! (axis-parallel ones, rays from inside primitives, rays aimed at primitives and exactly at their
//! vertices, rays along their edges, rays from points on the faces of their boxes, short
//! segments), and on degenerate inputs. Structures added later are checked here without a line
//! changed. Triangles are clipped exactly to the kd-tree's cells (and, in a second build, by their
//! boxes).

mod common;

use common::check_all_structures_clipped;
use common::rng::{Pcg32, RngExt, seeded};
use englobe::shapes::clip_triangle;
use englobe::{Aabb, Bounded, Intersect, PrimHit, Ray, Shape, Sphere, Triangle, Vec3};
use proptest::prelude::*;

/// Coordinates: mostly arbitrary, sometimes integers, so that shared edges, equal distances and
/// rays lying in box faces happen.
fn coord() -> impl Strategy<Value = f32> {
    prop_oneof![3 => -10.0f32..10.0, 1 => (-6i32..=6).prop_map(|i| i as f32)]
}

fn point() -> impl Strategy<Value = Vec3> {
    (coord(), coord(), coord()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn shape() -> impl Strategy<Value = Shape> {
    prop_oneof![
        (point(), prop_oneof![0.05f32..3.0, (1u8..=3).prop_map(f32::from)])
            .prop_map(|(c, r)| Shape::from(Sphere::new(c, r))),
        // Triangles near a random point, so that they stay small enough to be missed.
        (point(), point(), point()).prop_map(|(a, b, c)| Shape::from(Triangle::new(
            a,
            a + (b - a) * 0.3,
            a + (c - a) * 0.3
        ))),
    ]
}

/// Directions: random, axis-parallel (of both signs, with zeros of both signs), or in a plane.
fn direction() -> impl Strategy<Value = Vec3> {
    let axis = (0usize..3, prop::bool::ANY, prop::bool::ANY).prop_map(|(axis, negative, negative_zeros)| {
        let zero = if negative_zeros { -0.0 } else { 0.0 };
        let mut d = Vec3::splat(zero);
        d[axis] = if negative { -1.0 } else { 1.0 };
        d
    });
    let planar = (0usize..3, -1.0f32..1.0, -1.0f32..1.0).prop_map(|(axis, a, b)| {
        let mut d = Vec3::new(a, b, 1.0 - a.abs());
        d[axis] = 0.0;
        d
    });
    prop_oneof![4 => point(), 2 => axis, 1 => planar].prop_filter("a direction", |d| *d != Vec3::ZERO)
}

/// How a ray starts: anywhere, at a primitive's centre (inside it, or on a triangle), aimed at a
/// primitive's centre from anywhere, aimed exactly at a vertex (of a triangle, or a corner of a
/// sphere's box), along an edge (the line through two vertices, from before the first), or from a
/// point on a face of a primitive's box (a face of its leaf's box too: leaves are tight), edges and
/// corners of the face included.
#[derive(Clone, Debug)]
enum Start {
    Free(Vec3, Vec3),
    FromCentre(usize, Vec3),
    AtCentre(usize, Vec3),
    AtVertex(usize, usize, Vec3),
    AlongEdge(usize, usize, f32),
    OnFace(usize, usize, bool, [f32; 2], Vec3),
}

fn ray_spec() -> impl Strategy<Value = (Start, f32, f32)> {
    let index = || any::<prop::sample::Index>().prop_map(|i| i.index(usize::MAX));
    let face_uv = prop_oneof![Just(0.0f32), Just(0.5), Just(1.0), 0.0f32..1.0];
    let start = prop_oneof![
        2 => (point().prop_map(|p| p * 1.5), direction()).prop_map(|(o, d)| Start::Free(o, d)),
        1 => (index(), direction()).prop_map(|(i, d)| Start::FromCentre(i, d)),
        2 => (index(), point().prop_map(|p| p * 1.5)).prop_map(|(i, o)| Start::AtCentre(i, o)),
        1 => (index(), 0usize..8, point().prop_map(|p| p * 1.5)).prop_map(|(i, k, o)| Start::AtVertex(i, k, o)),
        1 => (index(), 0usize..3, prop_oneof![Just(0.0f32), 0.0f32..2.0]).prop_map(|(i, k, b)| Start::AlongEdge(i, k, b)),
        1 => (index(), 0usize..3, prop::bool::ANY, [face_uv.clone(), face_uv], direction())
            .prop_map(|(i, axis, max, uv, d)| Start::OnFace(i, axis, max, uv, d)),
    ];
    let range = prop_oneof![
        4 => Just((0.0f32, f32::INFINITY)),
        1 => (0.0f32..5.0, 0.0f32..20.0).prop_map(|(a, b)| (a, a + b)),
    ];
    (start, range).prop_map(|(s, (t0, t1))| (s, t0, t1))
}

/// The vertices of a shape: a triangle's three, or the eight corners of another shape's box.
fn vertices(shape: &Shape) -> Vec<Vec3> {
    match shape {
        Shape::Triangle(t) => t.vertices.to_vec(),
        s => {
            let b = s.bounds();
            (0..8)
                .map(|k| {
                    Vec3::new([b.min.x, b.max.x][k & 1], [b.min.y, b.max.y][k >> 1 & 1], [b.min.z, b.max.z][k >> 2])
                })
                .collect()
        }
    }
}

fn make_ray(shapes: &[Shape], (start, t_min, t_max): &(Start, f32, f32)) -> Ray {
    let n = shapes.len().max(1);
    let centre = |i: usize| shapes[i % n].bounds().center();
    let vertex = |i: usize, k: usize| {
        let v = vertices(&shapes[i % n]);
        v[k % v.len()]
    };
    let (origin, dir) = match *start {
        _ if shapes.is_empty() => (Vec3::ZERO, Vec3::Z),
        Start::Free(o, d) => (o, d),
        Start::FromCentre(i, d) => (centre(i), d),
        Start::AtCentre(i, o) if centre(i) != o => (o, centre(i) - o),
        Start::AtCentre(_, o) => (o, Vec3::Z),
        Start::AtVertex(i, k, o) if vertex(i, k) != o => (o, vertex(i, k) - o),
        Start::AtVertex(_, _, o) => (o, Vec3::Z),
        Start::AlongEdge(i, k, back) => {
            let (a, b) = (vertex(i, k), vertex(i, k + 1));
            if a == b { (a, Vec3::X) } else { (a - (b - a) * back, b - a) }
        }
        Start::OnFace(i, axis, max, [u, v], d) => {
            let b = shapes[i % n].bounds();
            let mut o = b.min + (b.max - b.min) * Vec3::new(u, v, u);
            o[(axis + 1) % 3] = b.min[(axis + 1) % 3] + (b.max - b.min)[(axis + 1) % 3] * u;
            o[(axis + 2) % 3] = b.min[(axis + 2) % 3] + (b.max - b.min)[(axis + 2) % 3] * v;
            o[axis] = if max { b.max[axis] } else { b.min[axis] };
            (o, d)
        }
    };
    Ray::segment(origin, dir, *t_min, *t_max)
}

fn check(shapes: &[Shape], rays: &[Ray]) -> Result<(), TestCaseError> {
    let boxes: Vec<Aabb> = shapes.iter().map(Bounded::bounds).collect();
    // Triangles are clipped exactly to the kd-tree's cells, other shapes by their boxes.
    let clip = |i: u32, cell: &Aabb| match &shapes[i as usize] {
        Shape::Triangle(t) => clip_triangle(t.vertices, cell),
        s => s.bounds().intersection(cell),
    };
    check_all_structures_clipped(&boxes, &clip, rays, |i, r| shapes[i as usize].intersect(r))
        .map_err(TestCaseError::fail)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 192, ..ProptestConfig::default() })]

    #[test]
    fn random_spheres_and_triangles(
        shapes in prop::collection::vec(shape(), 0..48),
        specs in prop::collection::vec(ray_spec(), 1..48),
    ) {
        let rays: Vec<Ray> = specs.iter().map(|s| make_ray(&shapes, s)).collect();
        check(&shapes, &rays)?;
    }

    #[test]
    fn many_primitives_few_rays(
        shapes in prop::collection::vec(shape(), 100..400),
        specs in prop::collection::vec(ray_spec(), 1..16),
    ) {
        let rays: Vec<Ray> = specs.iter().map(|s| make_ray(&shapes, s)).collect();
        check(&shapes, &rays)?;
    }

    #[test]
    fn copies_of_one_primitive_tie_to_the_lowest_index(
        original in shape(),
        copies in 1usize..40,
        specs in prop::collection::vec(ray_spec(), 1..24),
    ) {
        let shapes = vec![original; copies];
        let rays: Vec<Ray> = specs.iter().map(|s| make_ray(&shapes, s)).collect();
        check(&shapes, &rays)?;
    }
}

/// Rays through the origin along every axis and diagonal, from both sides.
fn star_rays() -> Vec<Ray> {
    let mut rays = Vec::new();
    for x in -1i32..=1 {
        for y in -1i32..=1 {
            for z in -1i32..=1 {
                let d = Vec3::new(x as f32, y as f32, z as f32);
                if d != Vec3::ZERO {
                    rays.push(Ray::new(-d * 20.0, d));
                    rays.push(Ray::new(Vec3::ZERO, d));
                    rays.push(Ray::new(Vec3::new(0.5, 0.25, 0.0) - d * 20.0, d));
                }
            }
        }
    }
    rays
}

#[test]
fn no_primitive_at_all() {
    check(&[], &star_rays()).unwrap();
}

#[test]
fn a_single_primitive() {
    check(&[Sphere::new(Vec3::ZERO, 1.0).into()], &star_rays()).unwrap();
    check(&[Triangle::new(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::Y).into()], &star_rays())
        .unwrap();
}

#[test]
fn identical_boxes() {
    // 64 copies of one sphere: every query ties, and the lowest index must win everywhere.
    let shapes = vec![Shape::from(Sphere::new(Vec3::ZERO, 1.0)); 64];
    check(&shapes, &star_rays()).unwrap();
    let boxes: Vec<Aabb> = shapes.iter().map(Bounded::bounds).collect();
    let hit = englobe::AnyAccel::build(englobe::AccelKind::BvhSeedOrdered, &boxes).bvh().map(|b| b.depth()).unwrap();
    assert_eq!(hit, 6);
}

#[test]
fn a_flat_grid_of_triangles_with_shared_edges() {
    // Two triangles per unit square on z = 0: rays along the grid lines and through vertices
    // must find exactly the triangle brute force finds.
    let mut shapes = Vec::new();
    for i in -4..4 {
        for j in -4..4 {
            let p = |a: i32, b: i32| Vec3::new(a as f32, b as f32, 0.0);
            shapes.push(Shape::from(Triangle::new(p(i, j), p(i + 1, j), p(i + 1, j + 1))));
            shapes.push(Shape::from(Triangle::new(p(i, j), p(i + 1, j + 1), p(i, j + 1))));
        }
    }
    let mut rays = star_rays();
    for a in -5..=5 {
        for b in -5..=5 {
            rays.push(Ray::new(Vec3::new(a as f32, b as f32, 3.0), -Vec3::Z));
            rays.push(Ray::new(Vec3::new(a as f32 * 0.5, b as f32 * 0.5, -3.0), Vec3::new(0.1, 0.0, 1.0)));
            // In the plane of the grid, along a grid line.
            rays.push(Ray::new(Vec3::new(a as f32, -10.0, 0.0), Vec3::Y));
        }
    }
    check(&shapes, &rays).unwrap();
}

#[test]
fn invalid_rays_hit_nothing_anywhere() {
    let shapes = vec![Shape::from(Sphere::new(Vec3::ZERO, 1.0)); 3];
    let rays = [
        Ray::new(Vec3::ZERO, Vec3::ZERO),
        Ray::new(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::X),
        Ray::segment(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 3.0, 2.0),
    ];
    check(&shapes, &rays).unwrap();
    let boxes: Vec<Aabb> = shapes.iter().map(Bounded::bounds).collect();
    for &kind in englobe::AccelKind::ALL {
        let accel = englobe::AnyAccel::build(kind, &boxes);
        for r in &rays {
            let mut c = englobe::WorkCounts::default();
            assert!(englobe::Accel::closest_hit(&accel, r, &mut c, |_, _| Some(PrimHit::at(0.0))).is_none());
            assert_eq!(c, englobe::WorkCounts::default(), "{kind} visited something for {r:?}");
        }
    }
}

#[test]
fn a_tie_in_a_subtree_entered_exactly_at_the_hit() {
    // Primitive 1 (a sphere) is hit at t = 5 first; primitive 0 (a triangle whose box the ray
    // enters at exactly t = 5) is hit at the same t and must win the tie by its lower index.
    let shapes = vec![
        Shape::from(Triangle::new(Vec3::new(-1.0, -1.0, 5.0), Vec3::new(5.0, -1.0, 5.0), Vec3::new(-1.0, 5.0, 5.0))),
        Shape::from(Sphere::new(Vec3::new(0.0, 0.0, 6.0), 1.0)),
    ];
    let ray = Ray::new(Vec3::ZERO, Vec3::Z);
    assert_eq!(shapes[0].intersect(&ray).map(|h| h.t), Some(5.0));
    assert_eq!(shapes[1].intersect(&ray).map(|h| h.t), Some(5.0));
    check(&shapes, &[ray]).unwrap();
}

/// The exact-mode scenes and rays, from the tests' generator.
struct Lattice(Pcg32);

impl Lattice {
    fn new(seed: u64) -> Self {
        Lattice(seeded(seed))
    }

    /// Uniform in `lo..=hi`.
    fn int(&mut self, lo: i32, hi: i32) -> i32 {
        self.0.random_range(lo..=hi)
    }

    fn point(&mut self) -> Vec3 {
        Vec3::new(self.int(-4, 4) as f32, self.int(-4, 4) as f32, self.int(-4, 4) as f32)
    }

    /// Triangles and spheres with integer vertices, centres and radii.
    fn scene(&mut self, n: usize) -> Vec<Shape> {
        (0..n)
            .map(|_| {
                if self.int(0, 3) == 0 {
                    Sphere::new(self.point(), self.int(1, 2) as f32).into()
                } else {
                    Triangle::new(self.point(), self.point(), self.point()).into()
                }
            })
            .collect()
    }

    /// Rays from integer points along the axes (both signs) and the diagonals of a face.
    fn axis_ray(&mut self) -> Ray {
        let mut d = Vec3::ZERO;
        d[self.int(0, 2) as usize] = if self.int(0, 1) == 0 { 1.0 } else { -1.0 };
        if self.int(0, 2) == 0 {
            d[(self.int(0, 2) as usize + 1) % 3] += if self.int(0, 1) == 0 { 1.0 } else { -1.0 };
        }
        let d = if d == Vec3::ZERO { Vec3::X } else { d };
        Ray::new(Vec3::new(self.int(-6, 6) as f32, self.int(-6, 6) as f32, self.int(-6, 6) as f32), d)
    }
}

/// Every primitive the ray hits anywhere along its interval, as `accel` finds them: its query is
/// told that nothing was hit, so it never shortens the interval and must offer every primitive
/// whose box the ray meets.
fn hit_set(accel: &englobe::AnyAccel, shapes: &[Shape], ray: &Ray) -> std::collections::BTreeSet<u32> {
    use englobe::Accel;
    let mut hits = std::collections::BTreeSet::new();
    accel.closest_hit(ray, &mut englobe::NoCount, |i, r| {
        if shapes[i as usize].intersect(r).is_some() {
            hits.insert(i);
        }
        None
    });
    hits
}

#[test]
fn exact_mode_integer_scenes_and_axis_rays_find_the_same_sets_of_hit_primitives() {
    let mut rng = Lattice::new(41);
    let mut compared = 0;
    for scene in 0..150 {
        let shapes = rng.scene(1 + scene % 40);
        let boxes: Vec<Aabb> = shapes.iter().map(Bounded::bounds).collect();
        let clip = |i: u32, cell: &Aabb| match &shapes[i as usize] {
            Shape::Triangle(t) => clip_triangle(t.vertices, cell),
            s => s.bounds().intersection(cell),
        };
        let rays: Vec<Ray> = (0..40).map(|_| rng.axis_ray()).collect();
        let brute = englobe::AnyAccel::build(englobe::AccelKind::None, &boxes);
        let expected: Vec<_> = rays.iter().map(|r| hit_set(&brute, &shapes, r)).collect();
        for &kind in englobe::AccelKind::ALL {
            let accel = englobe::AnyAccel::build_with_clipper(kind, &boxes, &clip);
            for (ray, want) in rays.iter().zip(&expected) {
                assert_eq!(&hit_set(&accel, &shapes, ray), want, "{kind}, scene {scene}: {ray:?}");
                compared += usize::from(!want.is_empty());
            }
        }
        check(&shapes, &rays).unwrap();
    }
    assert!(compared > 10_000, "only {compared} rays hit anything");
}

#[test]
fn every_size_from_0_to_64() {
    // Builds over the first n primitives of one scene, for every n: no panic, valid structures
    // (checked by the validators inside `check`), and the same answers as brute force.
    let mut rng = Lattice::new(7);
    let shapes = rng.scene(64);
    let rays: Vec<Ray> = (0..24).map(|_| rng.axis_ray()).chain(star_rays()).collect();
    for n in 0..=64 {
        check(&shapes[..n], &rays).unwrap_or_else(|e| panic!("{n} primitives: {e}"));
    }
}
