//! Whole worlds, every kind against brute force, bit for bit: random meshes (grids of triangles
//! sharing vertices and edges, and triangle soups), random instances of them under random
//! transforms (rotation, non-uniform scale, translation, mirroring), spheres, boxes, single
//! triangles and planes, and rays aimed exactly at vertices and along the edges that the meshes'
//! triangles share, seen in the world (through the instance's transform for an instance).
//!
//! This is what checks the fast path's two levels ([`AccelKind::BvhWide`]: every plain mesh in one
//! triangle structure, the shapes and instances in a wide BVH, the instanced meshes below) against
//! the flat world that brute force tests primitive by primitive: the same object, triangle, `t`,
//! `u` and `v`, and the same any-hit answer, with counting on and off.

use std::sync::Arc;

use englobe::accel::Validate;
use englobe::{
    AaBox, Aabb, AccelKind, Affine3A, Instance, NoCount, Object, Plane, Ray, Sphere, Triangle, TriangleMesh, Vec3,
    WorkCounts, World, WorldHit,
};
use glam::{EulerRot, Quat};
use proptest::prelude::*;

/// A mesh: a bumpy grid of `n x n` quads (two triangles each, sharing every inner edge and
/// vertex) or a soup of triangles near a point, placed around `at`.
#[derive(Clone, Debug)]
enum MeshSpec {
    Grid { n: u32, at: Vec3, size: f32, bumps: Vec<f32> },
    Soup { at: Vec3, corners: Vec<Vec3> },
}

fn mesh_of(spec: &MeshSpec) -> TriangleMesh {
    match spec {
        MeshSpec::Grid { n, at, size, bumps } => {
            let n = *n;
            let positions = (0..=n)
                .flat_map(|j| (0..=n).map(move |i| (i, j)))
                .map(|(i, j)| {
                    let bump = bumps[((i + j * (n + 1)) as usize) % bumps.len()];
                    *at + Vec3::new(i as f32 * size, bump, j as f32 * size)
                })
                .collect();
            let v = |i: u32, j: u32| i + j * (n + 1);
            let triangles = (0..n)
                .flat_map(|j| (0..n).map(move |i| (i, j)))
                .flat_map(|(i, j)| [[v(i, j), v(i + 1, j), v(i + 1, j + 1)], [v(i, j), v(i + 1, j + 1), v(i, j + 1)]])
                .collect();
            TriangleMesh::new(positions, triangles).expect("a valid grid")
        }
        MeshSpec::Soup { at, corners } => {
            let positions: Vec<Vec3> = corners.iter().map(|c| *at + *c).collect();
            let triangles = (0..positions.len() as u32 / 3).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
            TriangleMesh::new(positions, triangles).expect("a valid soup")
        }
    }
}

fn coord() -> impl Strategy<Value = f32> {
    prop_oneof![3 => -8.0f32..8.0, 1 => (-4i32..=4).prop_map(|i| i as f32)]
}

fn point() -> impl Strategy<Value = Vec3> {
    (coord(), coord(), coord()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn mesh_spec() -> impl Strategy<Value = MeshSpec> {
    prop_oneof![
        (1u32..6, point(), prop_oneof![0.25f32..2.0, Just(1.0)], prop::collection::vec(-0.5f32..0.5, 1..8))
            .prop_map(|(n, at, size, bumps)| MeshSpec::Grid { n, at, size, bumps }),
        (point(), prop::collection::vec((-1.5f32..1.5, -1.5f32..1.5, -1.5f32..1.5), 3..30)).prop_map(|(at, c)| {
            let corners: Vec<Vec3> = c.iter().map(|&(x, y, z)| Vec3::new(x, y, z)).collect();
            MeshSpec::Soup { at, corners: corners[..corners.len() / 3 * 3].to_vec() }
        }),
    ]
}

/// A placement: rotation, scale of each axis (one of them negative sometimes: a mirror), and a
/// translation.
fn transform() -> impl Strategy<Value = Affine3A> {
    let scale = prop_oneof![3 => 0.3f32..2.5, 1 => -2.0f32..-0.5, 1 => Just(1.0)];
    ((-3.2f32..3.2, -3.2f32..3.2, -3.2f32..3.2), (scale.clone(), scale.clone(), scale), point()).prop_map(
        |((a, b, c), (x, y, z), t)| {
            Affine3A::from_scale_rotation_translation(Vec3::new(x, y, z), Quat::from_euler(EulerRot::XYZ, a, b, c), t)
        },
    )
}

/// One object of a world; meshes are referred to by index so that instances share them.
#[derive(Clone, Debug)]
enum ObjectSpec {
    Mesh(usize),
    Instance(usize, Affine3A),
    Sphere(Vec3, f32),
    Box(Vec3, Vec3),
    Triangle(Vec3, Vec3, Vec3),
    Plane(Vec3, Vec3),
}

fn object_spec() -> impl Strategy<Value = ObjectSpec> {
    prop_oneof![
        3 => (0usize..4).prop_map(ObjectSpec::Mesh),
        4 => (0usize..4, transform()).prop_map(|(m, t)| ObjectSpec::Instance(m, t)),
        // In the same place as the plain mesh: ties at equal `t` between the two levels.
        1 => (0usize..4).prop_map(|m| ObjectSpec::Instance(m, Affine3A::IDENTITY)),
        1 => (point(), 0.1f32..2.0).prop_map(|(c, r)| ObjectSpec::Sphere(c, r)),
        1 => (point(), (0.1f32..2.0, 0.1f32..2.0, 0.0f32..2.0))
            .prop_map(|(a, (x, y, z))| ObjectSpec::Box(a, a + Vec3::new(x, y, z))),
        1 => (point(), point(), point()).prop_map(|(a, b, c)| ObjectSpec::Triangle(a, b, c)),
        1 => (point(), point()).prop_filter("a normal", |(_, n)| n.length() > 0.1)
            .prop_map(|(p, n)| ObjectSpec::Plane(p, n)),
    ]
}

fn world_objects(meshes: &[Arc<TriangleMesh>], specs: &[ObjectSpec]) -> Vec<Object> {
    specs
        .iter()
        .filter_map(|s| match s {
            ObjectSpec::Mesh(m) => Some(Object::Mesh(meshes[m % meshes.len()].clone())),
            // A transform too close to singular is refused: leave the object out.
            ObjectSpec::Instance(m, t) => Instance::new(meshes[m % meshes.len()].clone(), *t).ok().map(Object::from),
            ObjectSpec::Sphere(c, r) => Some(Sphere::new(*c, *r).into()),
            ObjectSpec::Box(a, b) => Some(AaBox::new(*a, *b).into()),
            ObjectSpec::Triangle(a, b, c) => Some(Triangle::new(*a, *b, *c).into()),
            ObjectSpec::Plane(p, n) => Plane::new(*n, *p).map(Object::from),
        })
        .collect()
}

/// How a ray is aimed: anywhere, at a vertex of an object's mesh, or along or across an edge of
/// one of its triangles (`along` picks the point on the edge), seen in the world.
#[derive(Clone, Debug)]
enum RaySpec {
    Free { origin: Vec3, dir: Vec3 },
    Vertex { origin: Vec3, object: usize, vertex: usize },
    Edge { origin: Vec3, object: usize, triangle: usize, edge: usize, along: f32 },
}

fn ray_spec() -> impl Strategy<Value = RaySpec> {
    let far = || point().prop_map(|p| p * 2.0);
    prop_oneof![
        1 => (far(), point()).prop_map(|(origin, dir)| RaySpec::Free { origin, dir }),
        2 => (far(), any::<usize>(), any::<usize>())
            .prop_map(|(origin, object, vertex)| RaySpec::Vertex { origin, object, vertex }),
        2 => (far(), any::<usize>(), any::<usize>(), 0usize..3, prop_oneof![Just(0.5f32), 0.0f32..1.0])
            .prop_map(|(origin, object, triangle, edge, along)| RaySpec::Edge { origin, object, triangle, edge, along }),
    ]
}

/// The mesh of an object and its placement in the world, if it has one.
fn placed_mesh(object: &Object) -> Option<(&TriangleMesh, Affine3A)> {
    match object {
        Object::Mesh(m) => Some((m, Affine3A::IDENTITY)),
        Object::Instance(i) => Some((i.mesh(), *i.to_world())),
        Object::Shape(_) => None,
    }
}

fn make_ray(objects: &[Object], spec: &RaySpec) -> Ray {
    let meshes: Vec<(&TriangleMesh, Affine3A)> = objects.iter().filter_map(placed_mesh).collect();
    let aimed = |origin: Vec3, target: Vec3| {
        let d = target - origin;
        Ray::new(origin, if d == Vec3::ZERO { Vec3::X } else { d })
    };
    match spec {
        RaySpec::Free { origin, dir } => Ray::new(*origin, if *dir == Vec3::ZERO { Vec3::Y } else { *dir }),
        RaySpec::Vertex { origin, object, vertex } if !meshes.is_empty() => {
            let (mesh, to_world) = meshes[object % meshes.len()];
            aimed(*origin, to_world.transform_point3(mesh.positions()[vertex % mesh.positions().len()]))
        }
        RaySpec::Edge { origin, object, triangle, edge, along } if !meshes.is_empty() => {
            let (mesh, to_world) = meshes[object % meshes.len()];
            let tri = mesh.triangles()[triangle % mesh.len()];
            let a = mesh.positions()[tri[*edge] as usize];
            let b = mesh.positions()[tri[(edge + 1) % 3] as usize];
            aimed(*origin, to_world.transform_point3(a + (b - a) * *along))
        }
        RaySpec::Vertex { origin, .. } | RaySpec::Edge { origin, .. } => aimed(*origin, Vec3::ZERO),
    }
}

/// The box of every primitive by its world number (objects in order, a plain mesh's triangles one
/// by one), empty for those that are not mesh triangles: what the fast path's triangle structure
/// is checked against.
fn triangle_boxes(objects: &[Object]) -> Vec<Aabb> {
    objects
        .iter()
        .flat_map(|o| match o {
            Object::Mesh(m) => (0..m.len() as u32).map(|t| m.triangle_bounds(t)).collect(),
            Object::Shape(s) if !s.is_bounded() => vec![],
            _ => vec![Aabb::EMPTY],
        })
        .collect()
}

/// Every kind against brute force: the same hit bit for bit, the same any-hit answer, whether
/// work is counted or not, ray by ray, in packets and in batches.
fn check(objects: Vec<Object>, rays: &[Ray]) -> Result<(), TestCaseError> {
    let brute = World::build(objects.clone(), AccelKind::None).expect("finite objects");
    let expected: Vec<(Option<WorldHit>, bool)> =
        rays.iter().map(|r| (brute.closest_hit(r, &mut NoCount), brute.any_hit(r, &mut NoCount))).collect();
    for &kind in AccelKind::ALL {
        let world = World::build(objects.clone(), kind).expect("finite objects");
        prop_assert_eq!(world.primitive_count(), brute.primitive_count());
        if let Some(triangles) = world.triangles() {
            let stats = triangles.validate(&triangle_boxes(&objects), None);
            prop_assert!(stats.is_ok(), "{}: {:?}", kind, stats.err());
        }
        for (ray, (closest, any)) in rays.iter().zip(&expected) {
            let got = world.closest_hit(ray, &mut NoCount);
            prop_assert_eq!(got, *closest, "{}: closest hit of {:?}", kind, ray);
            let counted = world.closest_hit(ray, &mut WorkCounts::default());
            prop_assert_eq!(counted, got, "{}: counting changed the closest hit of {:?}", kind, ray);
            prop_assert_eq!(world.any_hit(ray, &mut NoCount), *any, "{}: any hit of {:?}", kind, ray);
            prop_assert_eq!(world.any_hit(ray, &mut WorkCounts::default()), *any, "{}: counted any hit", kind);
        }
        // Packets of sixteen consecutive rays (through the triangle tree and the top level
        // together, on the fast path), coherent or not, and the batches that choose.
        let (mut packet, mut batch) = (vec![None; rays.len()], vec![None; rays.len()]);
        let (mut packet_any, mut batch_any) = (vec![false; rays.len()], vec![false; rays.len()]);
        world.closest_hit_packet(rays, &mut packet, &mut WorkCounts::default()).expect("as many hits as rays");
        world.any_hit_packet(rays, &mut packet_any, &mut NoCount).expect("as many answers as rays");
        world.closest_hits(rays, &mut batch).expect("as many hits as rays");
        world.any_hits(rays, &mut batch_any).expect("as many answers as rays");
        for (i, (closest, any)) in expected.iter().enumerate() {
            prop_assert_eq!(packet[i], *closest, "{}: packet closest hit of {:?}", kind, rays[i]);
            prop_assert_eq!(batch[i], *closest, "{}: batch closest hit of {:?}", kind, rays[i]);
            prop_assert_eq!(packet_any[i], *any, "{}: packet any hit of {:?}", kind, rays[i]);
            prop_assert_eq!(batch_any[i], *any, "{}: batch any hit of {:?}", kind, rays[i]);
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn random_worlds_of_meshes_instances_and_shapes(
        meshes in prop::collection::vec(mesh_spec(), 1..4),
        specs in prop::collection::vec(object_spec(), 0..24),
        rays in prop::collection::vec(ray_spec(), 1..64),
    ) {
        let meshes: Vec<Arc<TriangleMesh>> = meshes.iter().map(|m| Arc::new(mesh_of(m))).collect();
        let objects = world_objects(&meshes, &specs);
        let rays: Vec<Ray> = rays.iter().map(|s| make_ray(&objects, s)).collect();
        check(objects, &rays)?;
    }
}

/// A field of instances of one grid and the same grid as a plain mesh, hit along every shared
/// edge and at every shared vertex: the fast path's triangle structure and its bottom levels
/// answer as brute force does where the triangles meet. An instance in the same place as the
/// plain grid, before it, and a single triangle on the grid's first one, after it, tie with it at
/// every hit: the lower object must win.
#[test]
fn shared_vertices_and_edges_of_plain_and_instanced_grids() {
    let grid = Arc::new(mesh_of(&MeshSpec::Grid { n: 6, at: Vec3::ZERO, size: 1.0, bumps: vec![0.0, 0.25, -0.125] }));
    let first = grid.triangle(0).vertices;
    let mut objects: Vec<Object> = vec![
        Instance::new(grid.clone(), Affine3A::IDENTITY).unwrap().into(),
        Object::Mesh(grid.clone()),
        Triangle::new(first[0], first[1], first[2]).into(),
    ];
    for k in 0..12 {
        let m = Affine3A::from_scale_rotation_translation(
            Vec3::new(1.0 + 0.1 * k as f32, 1.0, 0.75),
            Quat::from_rotation_y(0.4 * k as f32),
            Vec3::new(8.0 + 3.0 * (k % 4) as f32, 0.5 * k as f32, 3.0 * (k / 4) as f32),
        );
        objects.push(Instance::new(grid.clone(), m).unwrap().into());
    }
    objects.push(Sphere::new(Vec3::new(3.0, 2.0, 3.0), 1.0).into());
    objects.push(Plane::new(Vec3::Y, Vec3::new(0.0, -1.0, 0.0)).unwrap().into());
    let origin = Vec3::new(2.7, 9.0, -4.1);
    let mut rays = Vec::new();
    for object in &objects {
        let Some((mesh, to_world)) = placed_mesh(object) else { continue };
        for p in mesh.positions() {
            rays.push(Ray::new(origin, to_world.transform_point3(*p) - origin));
        }
        for tri in mesh.triangles() {
            for e in 0..3 {
                let (a, b) = (mesh.positions()[tri[e] as usize], mesh.positions()[tri[(e + 1) % 3] as usize]);
                rays.push(Ray::new(origin, to_world.transform_point3((a + b) * 0.5) - origin));
            }
        }
    }
    assert!(rays.len() > 13 * 49, "{} rays", rays.len());
    let brute = World::build(objects.clone(), AccelKind::None).unwrap();
    let on_the_grid = rays.iter().filter(|r| brute.closest_hit(r, &mut NoCount).is_some_and(|h| h.object == 0)).count();
    let on_instances = rays.iter().filter(|r| brute.closest_hit(r, &mut NoCount).is_some_and(|h| h.object > 2)).count();
    assert!(on_the_grid > 100 && on_instances > 200, "{on_the_grid} rays on the grid, {on_instances} on instances");
    check(objects, &rays).unwrap();
}
