//! The shapes a ray can hit, each with its exact intersection, its normal and its own bounding box
//! (the seed report's "one bounding-box function per kind of object"), plus meshes and instances
//! of meshes.

mod aabox;
pub(crate) mod clip;
mod closest_point;
mod instance;
mod interface;
mod mesh;
mod plane;
mod sphere;
mod triangle;
mod triangle_box;

pub use aabox::AaBox;
pub use clip::clip_triangle;
pub use closest_point::{closest_point_on_triangle, distance_squared, distance_squared_to_box};
pub use instance::{Instance, InstanceError, transform_box};
pub(crate) use mesh::triples;
pub use mesh::{MeshError, TriangleMesh, check_arrays};
pub use plane::Plane;
pub use sphere::Sphere;
pub use triangle::{Triangle, WatertightRay, intersect_triangle, is_degenerate};
pub use triangle_box::triangle_overlaps_box;

pub use interface::{Bounded, Intersect};

use glam::Vec3;

use crate::{Aabb, PrimHit, Ray};

/// One shape of any kind, the unit a [`crate::World`] is made of.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A sphere.
    Sphere(Sphere),
    /// An infinite plane (unbounded: kept beside the acceleration structure).
    Plane(Plane),
    /// An axis-aligned box.
    AaBox(AaBox),
    /// A triangle.
    Triangle(Triangle),
}

impl Shape {
    /// False for shapes with no finite bounding box, which acceleration structures cannot hold.
    pub fn is_bounded(&self) -> bool {
        !matches!(self, Shape::Plane(_))
    }
}

macro_rules! dispatch {
    ($self:ident, $s:ident => $e:expr) => {
        match $self {
            Shape::Sphere($s) => $e,
            Shape::Plane($s) => $e,
            Shape::AaBox($s) => $e,
            Shape::Triangle($s) => $e,
        }
    };
}

impl Bounded for Shape {
    fn bounds(&self) -> Aabb {
        dispatch!(self, s => s.bounds())
    }
}

impl Intersect for Shape {
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<PrimHit> {
        dispatch!(self, s => s.intersect(ray))
    }

    fn normal(&self, p: Vec3, hit: &PrimHit) -> Vec3 {
        dispatch!(self, s => s.normal(p, hit))
    }
}

macro_rules! impl_from {
    ($($t:ident),*) => {$(
        impl From<$t> for Shape {
            fn from(s: $t) -> Self {
                Shape::$t(s)
            }
        }
    )*};
}
impl_from!(Sphere, Plane, AaBox, Triangle);
