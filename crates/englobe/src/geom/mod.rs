//! The ground floor: rays ([`Ray`]), axis-aligned boxes and the robust slab test ([`Aabb`]), and
//! where a ray meets one primitive ([`PrimHit`]). Everything else builds on these; they import
//! nothing of the crate.

pub mod aabb;
pub mod huge_pages;
pub mod prefetch;
pub mod prim_hit;
pub mod ray;

pub use aabb::Aabb;
pub use prim_hit::PrimHit;
pub use ray::Ray;
