//! # englobe
//!
//! Ray queries accelerated by bounding volumes. The name comes from the French *volumes
//! englobants*: bounding volumes, the answer a 2009 student report gave to the question "which
//! objects can a ray possibly hit?", and the thread this library follows.
//!
//! * Geometry: [`Ray`], [`Aabb`], [`PrimHit`] ([`geom`]) and the [`shapes`] (sphere, plane, box,
//!   triangle, mesh, instance).
//! * Acceleration structures behind one interface, [`accel::Accel`], with work counters; the
//!   fast path for triangle meshes, [`TriangleBvh`] (eight-wide SIMD nodes, triangles in blocks
//!   of four in the leaves).
//! * [`World`]: objects plus structures, answering closest-hit, any-hit, batch, point and box
//!   queries in terms of objects.
//!
//! Every structure answers as brute force does, bit for bit: the same watertight triangle test
//! everywhere, ties at equal distance to the lower index.
//!
//! # A guide
//!
//! ## Build from plain arrays
//!
//! Vertex positions as `[f32; 3]`, triangles as three `u32` indices: no other type needed. The
//! indices are checked (an error, never a panic), and the arrays are read in place.
//!
//! ```
//! use englobe::{NoCount, Ray, TriangleBvh, Vec3};
//!
//! // A unit square in the plane z = 0, two triangles.
//! let vertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
//! let triangles = [[0, 1, 2], [0, 2, 3]];
//! let bvh = TriangleBvh::from_arrays(&vertices, &triangles)?;
//! assert!(TriangleBvh::from_arrays(&vertices, &[[0, 1, 4]]).is_err(), "vertex 4 does not exist");
//! # Ok::<(), englobe::shapes::MeshError>(())
//! ```
//!
//! [`TriangleMesh::from_arrays`] does the same for a mesh that a [`World`] holds beside spheres,
//! boxes, planes and instances; glam's types ([`Vec3`], [`Affine3A`]) work everywhere too.
//!
//! ## Query
//!
//! Two queries, always: the closest hit within the ray's interval (`t`, the triangle, its
//! barycentrics), and whether anything is hit (shadow rays, line of sight). Both take `&self`,
//! so any number of threads may query at once, and a counter ([`NoCount`], or [`WorkCounts`] to
//! count the work).
//!
//! ```
//! # use englobe::{NoCount, Ray, TriangleBvh, Vec3};
//! # let bvh = TriangleBvh::from_arrays(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 2], [0, 2, 3]])?;
//! let down = Ray::new(Vec3::new(0.25, 0.75, 2.0), -Vec3::Z);
//! let hit = bvh.closest_hit(&down, &mut NoCount).expect("the square");
//! assert_eq!((hit.prim, hit.t), (1, 2.0));
//! // A segment: from the origin, 1.5 units along the direction.
//! assert!(!bvh.any_hit(&Ray::segment(Vec3::new(0.25, 0.75, 2.0), -Vec3::Z, 0.0, 1.5), &mut NoCount));
//! # Ok::<(), englobe::shapes::MeshError>(())
//! ```
//!
//! ## Batches
//!
//! A slice of rays in, a slice of answers out, split across threads when the batch is large
//! (the `parallel` feature), nothing allocated per ray. Sixteen consecutive rays that are
//! coherent (a camera's tile, a lidar's fan) walk the tree together as a packet; the others go
//! one by one. `closest_hit_packet` and `any_hit_packet` ask for packets whatever the rays. Every
//! ray gets its single-ray answer, bit for bit.
//!
//! ```
//! # use englobe::{NoCount, Ray, TriangleBvh, Vec3};
//! # let bvh = TriangleBvh::from_arrays(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 2], [0, 2, 3]])?;
//! let rays: Vec<Ray> = (0..4096).map(|i| Ray::new(Vec3::new(i as f32 / 2048.0, 0.5, 1.0), -Vec3::Z)).collect();
//! let mut hits = vec![None; rays.len()];
//! bvh.closest_hits(&rays, &mut hits)?;
//! let mut mask = vec![false; rays.len()];
//! bvh.any_hits(&rays, &mut mask)?;
//! assert!(mask[100] && !mask[4000] && hits[100].is_some());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## Move
//!
//! When the vertices move and the triangles stay the same, [`TriangleBvh::refit_arrays`] (or
//! [`TriangleBvh::refit`]) recomputes the boxes instead of rebuilding, about ten times faster on
//! the Stanford bunny, and reports the tree's SAH cost so that the caller can rebuild when the
//! refitted tree has grown too loose.
//!
//! ```
//! # use englobe::{NoCount, Ray, TriangleBvh, Vec3};
//! let mut vertices = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
//! let triangles = [[0, 1, 2], [0, 2, 3]];
//! let mut bvh = TriangleBvh::from_arrays(&vertices, &triangles)?;
//! vertices[2][2] = 1.0; // one corner lifted
//! let report = bvh.refit_arrays(&vertices, &triangles)?;
//! if report.cost_ratio() > 2.0 {
//!     bvh = TriangleBvh::from_arrays(&vertices, &triangles)?;
//! }
//! let hit = bvh.closest_hit(&Ray::new(Vec3::new(0.9, 0.5, 2.0), -Vec3::Z), &mut NoCount).expect("a hit");
//! assert!(hit.t < 2.0, "the lifted corner is nearer");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## Filter
//!
//! A closure that rejects candidate hits (a cut-out texture, the surface a ray starts from, the
//! objects a sensor should not see), for both queries; absent ([`NoFilter`]), it costs nothing.
//!
//! ```
//! # use englobe::{Hit, NoCount, Ray, TriangleBvh, Vec3};
//! # let bvh = TriangleBvh::from_arrays(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 2], [0, 2, 3]])?;
//! let through_triangle_1 = Ray::new(Vec3::new(0.25, 0.75, 2.0), -Vec3::Z);
//! assert!(!bvh.any_hit_filtered(&through_triangle_1, &mut NoCount, |h: &Hit| h.prim != 1));
//! # Ok::<(), englobe::shapes::MeshError>(())
//! ```
//!
//! ## Points and boxes
//!
//! The closest point of the mesh to a point within a radius (Embree's `rtcPointQuery`, parry's
//! `project_point`), and the triangles that overlap a box, both exact.
//!
//! ```
//! # use englobe::{Aabb, TriangleBvh, Vec3};
//! # let bvh = TriangleBvh::from_arrays(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 2], [0, 2, 3]])?;
//! let near = bvh.closest_point(Vec3::new(2.0, 0.5, 0.0), 5.0).expect("within 5");
//! assert_eq!((near.prim, near.point, near.distance), (0, Vec3::new(1.0, 0.5, 0.0), 1.0));
//! assert_eq!(bvh.triangles_in_box(&Aabb::new(Vec3::new(0.8, 0.0, -1.0), Vec3::new(1.0, 0.1, 1.0))), vec![0]);
//! # Ok::<(), englobe::shapes::MeshError>(())
//! ```
//!
//! ## Worlds
//!
//! A [`World`] holds meshes, instances of meshes and shapes, with the same queries answered in
//! terms of objects ([`WorldHit`]: the object, its primitive, `t`).
//!
//! ```
//! use englobe::{AccelKind, NoCount, Ray, Sphere, Vec3, World};
//!
//! let world = World::build(vec![Sphere::new(Vec3::new(0.0, 0.0, 5.0), 1.0).into()], AccelKind::BvhWide)?;
//! let hit = world.closest_hit(&Ray::new(Vec3::ZERO, Vec3::Z), &mut NoCount).expect("a hit");
//! assert_eq!((hit.object, hit.t), (0, 4.0));
//! # Ok::<(), englobe::WorldError>(())
//! ```
//!
//! # Features, Rust version, stability
//!
//! * `parallel` (default): rayon for builds, refits and large batches. Without it everything
//!   runs on the calling thread, with the same answers.
//! * The minimum supported Rust version is 1.89 (the AVX-512 kernels' target features); raising
//!   it is a minor-version change.
//! * The crate follows semantic versioning; before 1.0, a breaking change bumps the minor version
//!   (0.1 to 0.2) and is listed in the CHANGELOG.
//! * The instruction set is chosen at run time (AVX-512, AVX2, or portable code), so one binary
//!   runs on any x86-64, at full speed where it can.

pub mod accel;
pub mod geom;
pub mod shapes;
pub mod world;

pub use accel::{
    Accel, AccelKind, AnyAccel, ClosestPoint, Counters, Hit, HitFilter, NoCount, NoFilter, PacketHits, RayPacket,
    TriangleBvh, WideBvh, WorkCounts,
};
pub use geom::{Aabb, PrimHit, Ray};
pub use glam::{Affine3A, Mat4, Vec2, Vec3};
pub use shapes::{AaBox, Bounded, Instance, Intersect, Plane, Shape, Sphere, Triangle, TriangleMesh};
pub use world::{BottomLevel, Object, World, WorldError, WorldHit, WorldPoint};

// The README's examples are compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
struct ReadmeDoctests;
