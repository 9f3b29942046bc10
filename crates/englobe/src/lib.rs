//! # englobe
//!
//! Ray queries accelerated by bounding volumes. The name comes from the French *volumes
//! englobants*: bounding volumes, the answer a 2009 student report gave to the question "which
//! objects can a ray possibly hit?", and the thread this library follows.
//!
//! * Geometry: [`Ray`], [`Aabb`], [`PrimHit`] ([`geom`]) and the [`shapes`] (sphere, plane, box,
//!   triangle, mesh, instance).
//! * Acceleration structures behind one interface, [`accel::Accel`], with work counters.
//! * [`World`]: objects plus a structure, answering closest-hit and any-hit queries.
//!
//! ```
//! use englobe::{AccelKind, NoCount, Ray, Sphere, Vec3, World};
//!
//! let world = World::build(vec![Sphere::new(Vec3::new(0.0, 0.0, 5.0), 1.0).into()], AccelKind::None)?;
//! let hit = world.closest_hit(&Ray::new(Vec3::ZERO, Vec3::Z), &mut NoCount).expect("a hit");
//! assert_eq!((hit.object, hit.t), (0, 4.0));
//! # Ok::<(), englobe::WorldError>(())
//! ```

pub mod accel;
pub mod geom;
pub mod shapes;
pub mod world;

pub use accel::{
    Accel, AccelKind, AnyAccel, ClosestPoint, Counters, Hit, HitFilter, NoCount, NoFilter, TriangleBvh, WideBvh,
    WorkCounts,
};
pub use geom::{Aabb, PrimHit, Ray};
pub use glam::{Affine3A, Mat4, Vec2, Vec3};
pub use shapes::{AaBox, Bounded, Instance, Intersect, Plane, Shape, Sphere, Triangle, TriangleMesh};
pub use world::{BottomLevel, Object, World, WorldError, WorldHit, WorldPoint};

// The README's examples are compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
struct ReadmeDoctests;
