//! What every shape offers: its box ([`Bounded`], the seed report's "one bounding-box function
//! per kind of object") and its exact test and normal ([`Intersect`]).

use glam::Vec3;

use crate::{Aabb, PrimHit, Ray};

/// Anything with a bounding box. Unbounded shapes (planes) return a box with infinite corners.
pub trait Bounded {
    /// The tightest axis-aligned box around the shape.
    fn bounds(&self) -> Aabb;
}

/// A shape a ray can be tested against exactly.
pub trait Intersect: Bounded {
    /// The nearest hit with `t` in the ray's interval `t_min..=t_max`, if any.
    fn intersect(&self, ray: &Ray) -> Option<PrimHit>;

    /// The unit geometric normal at the surface point `p` of `hit`. It points outward for closed
    /// shapes and along the winding's right-hand normal for triangles, whichever side the ray came from.
    fn normal(&self, p: Vec3, hit: &PrimHit) -> Vec3;
}
