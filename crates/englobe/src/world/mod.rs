//! A world: a list of objects (shapes, meshes and mesh instances) with an acceleration structure
//! over their bounded primitives. It answers closest-hit and any-hit queries in terms of objects,
//! which is what a renderer or any other user of ray queries needs.
//!
//! Every bounded primitive (a sphere, a box, one triangle of a mesh, one whole instance) gets an
//! index in the order the objects were given, and the structure is built over their boxes.
//! Unbounded shapes (planes) stay outside the structure and are tested beside it, as the design of
//! every production ray tracer does. Instances make a two-level hierarchy: see [`BottomLevel`].
//! Structures that split primitives across cells (the kd-tree) get each triangle's exact part in a
//! cell ([`clip_triangle`]), and the box's part for other shapes.

use std::sync::Arc;

use glam::Vec3;

mod instances;

use crate::accel::{Accel, AccelKind, AnyAccel, Counters, HitRecord, MAX_PRIMITIVES, StructureStats};
use crate::shapes::{Bounded, Instance, Intersect, PrimHit, Shape, TriangleMesh, WatertightRay, clip_triangle};
use crate::{Aabb, Ray};

pub use instances::BottomLevel;

/// One object of a world.
#[derive(Clone, Debug, PartialEq)]
pub enum Object {
    /// A single shape.
    Shape(Shape),
    /// A triangle mesh: each triangle is a primitive of its own.
    Mesh(Arc<TriangleMesh>),
    /// A mesh placed by a transform: one primitive of the world's structure, traced through a
    /// bottom-level structure over the mesh that all instances of the same mesh share.
    Instance(Instance),
}

impl<S: Into<Shape>> From<S> for Object {
    fn from(s: S) -> Self {
        Object::Shape(s.into())
    }
}

impl From<TriangleMesh> for Object {
    fn from(m: TriangleMesh) -> Self {
        Object::Mesh(Arc::new(m))
    }
}

impl From<Instance> for Object {
    fn from(i: Instance) -> Self {
        Object::Instance(i)
    }
}

impl Object {
    /// Number of primitives the object contributes to the world's structure.
    pub fn primitive_count(&self) -> usize {
        match self {
            Object::Shape(_) | Object::Instance(_) => 1,
            Object::Mesh(m) => m.len(),
        }
    }

    /// Number of triangles the object puts in the picture (an instance counts its mesh's).
    pub fn triangle_count(&self) -> usize {
        match self {
            Object::Shape(Shape::Triangle(_)) => 1,
            Object::Shape(_) => 0,
            Object::Mesh(m) => m.len(),
            Object::Instance(i) => i.mesh().len(),
        }
    }
}

/// Why a world could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WorldError {
    /// A bounded shape has a box with NaN or infinite corners.
    #[error("object {object} has non-finite bounds {bounds:?}")]
    NonFiniteBounds {
        /// Object index.
        object: usize,
        /// Its box.
        bounds: Aabb,
    },
    /// More primitives than a structure can hold ([`MAX_PRIMITIVES`]).
    #[error("too many primitives: {0}")]
    TooManyPrimitives(usize),
}

/// Where a ray hit a world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldHit {
    /// Ray parameter.
    pub t: f32,
    /// Index of the object hit, in the order the objects were given.
    pub object: u32,
    /// Index of the primitive within that object: the triangle of a mesh, the triangle of the
    /// instanced mesh for an instance, 0 for shapes.
    pub prim: u32,
    /// First surface coordinate.
    pub u: f32,
    /// Second surface coordinate.
    pub v: f32,
}

/// Objects plus an acceleration structure over their bounded primitives.
#[derive(Clone, Debug)]
pub struct World {
    objects: Vec<Object>,
    /// For each structure primitive, its object.
    prim_object: Vec<u32>,
    /// For each object, the index of its first structure primitive.
    object_first_prim: Vec<u32>,
    /// Objects tested beside the structure.
    unbounded: Vec<u32>,
    accel: AnyAccel,
    kind: AccelKind,
    /// Bottom-level structures, one per distinct instanced mesh, shared by its instances.
    bottom: Vec<BottomLevel>,
    /// For each object, the index of its bottom-level structure (instances only).
    object_bottom: Vec<u32>,
}

impl World {
    /// Builds a world over `objects` with the structure `kind`. Instances of the same mesh (the
    /// same `Arc`) share one bottom-level structure, also of kind `kind`.
    pub fn build(objects: Vec<Object>, kind: AccelKind) -> Result<World, WorldError> {
        let total: usize = objects
            .iter()
            .map(|o| match o {
                Object::Shape(s) if !s.is_bounded() => 0,
                o => o.primitive_count(),
            })
            .sum();
        if total > MAX_PRIMITIVES {
            return Err(WorldError::TooManyPrimitives(total));
        }
        let mut boxes = Vec::with_capacity(total);
        let mut prim_object = Vec::with_capacity(total);
        let mut object_first_prim = Vec::with_capacity(objects.len());
        let mut unbounded = Vec::new();
        for (i, object) in objects.iter().enumerate() {
            object_first_prim.push(boxes.len() as u32);
            match object {
                Object::Shape(s) if !s.is_bounded() => unbounded.push(i as u32),
                Object::Shape(s) => {
                    let b = s.bounds();
                    if !b.is_finite() {
                        return Err(WorldError::NonFiniteBounds { object: i, bounds: b });
                    }
                    boxes.push(b);
                    prim_object.push(i as u32);
                }
                Object::Mesh(m) => {
                    // Mesh construction guarantees finite vertices, so every box is finite.
                    boxes.extend((0..m.len() as u32).map(|t| m.triangle_bounds(t)));
                    prim_object.resize(boxes.len(), i as u32);
                }
                Object::Instance(inst) => {
                    // Instance construction guarantees finite bounds.
                    boxes.push(inst.bounds());
                    prim_object.push(i as u32);
                }
            }
        }
        // Split clipping: a triangle's exact part in a cell, any other shape's box's part.
        let clip = |prim: u32, cell: &Aabb| {
            let object = prim_object[prim as usize];
            match &objects[object as usize] {
                Object::Mesh(m) => clip_triangle(m.triangle(prim - object_first_prim[object as usize]).vertices, cell),
                Object::Shape(Shape::Triangle(t)) => clip_triangle(t.vertices, cell),
                _ => boxes[prim as usize].intersection(cell),
            }
        };
        let accel = AnyAccel::build_with_clipper(kind, &boxes, &clip);
        drop(boxes);
        let (bottom, object_bottom) = instances::build_bottom_levels(&objects, kind);
        Ok(World { objects, prim_object, object_first_prim, unbounded, accel, kind, bottom, object_bottom })
    }

    /// The objects, in the order given.
    pub fn objects(&self) -> &[Object] {
        &self.objects
    }

    /// The structure's kind.
    pub fn accel_kind(&self) -> AccelKind {
        self.kind
    }

    /// The structure itself.
    pub fn accel(&self) -> &AnyAccel {
        &self.accel
    }

    /// Size and shape of the (top-level) structure.
    pub fn stats(&self) -> StructureStats {
        self.accel.stats()
    }

    /// The bottom-level structures, one per distinct instanced mesh.
    pub fn bottom_levels(&self) -> &[BottomLevel] {
        &self.bottom
    }

    /// Triangles in the picture, every instance counting its mesh's.
    pub fn triangle_count(&self) -> usize {
        self.objects.iter().map(Object::triangle_count).sum()
    }

    /// Number of primitives in the structure (unbounded shapes not included).
    pub fn primitive_count(&self) -> usize {
        self.prim_object.len()
    }

    /// Box around the bounded primitives.
    pub fn bounds(&self) -> Aabb {
        self.accel.bounds()
    }

    #[inline(always)]
    fn locate(&self, prim: u32) -> (u32, u32) {
        let object = self.prim_object[prim as usize];
        (object, prim - self.object_first_prim[object as usize])
    }

    /// The closest hit, or `None`. Ties at equal `t` go to the lower object (then primitive) index.
    pub fn closest_hit<C: Counters>(&self, ray: &Ray, counters: &mut C) -> Option<WorldHit> {
        if !ray.is_valid() {
            return None;
        }
        // Work inside instances is counted apart (the structure holds `counters` during its query)
        // and merged afterwards.
        let mut nested = C::default();
        let mut instance_hits = instances::ClosestInstance::default();
        let w = WatertightRay::new(ray);
        let found = self.accel.closest_hit(ray, counters, |prim, r| {
            let (object, local) = self.locate(prim);
            match &self.objects[object as usize] {
                Object::Shape(s) => s.intersect(r),
                Object::Mesh(m) => m.intersect_with(local, r, &w),
                Object::Instance(inst) => {
                    let hit = self.instance_closest_hit(object, inst, r, &mut nested)?;
                    instance_hits.offer(prim, &hit);
                    Some(PrimHit { t: hit.t, u: hit.u, v: hit.v })
                }
            }
        });
        counters.merge(&nested);
        let mut best = found.map(|h| {
            let (object, local) = self.locate(h.prim);
            let prim = match &self.objects[object as usize] {
                Object::Instance(inst) => instance_hits.triangle(h.prim, h.t).unwrap_or_else(|| {
                    // Only a structure that breaks the tie rule of `HitRecord::offer` gets here:
                    // ask the instance again, up to the hit.
                    let r = ray.with_range(ray.t_min, h.t);
                    self.instance_closest_hit(object, inst, &r, &mut C::default()).map_or(0, |x| x.prim)
                }),
                _ => local,
            };
            WorldHit { t: h.t, object, prim, u: h.u, v: h.v }
        });
        let mut record = HitRecord::new(ray.with_range(ray.t_min, best.map_or(ray.t_max, |b| b.t)));
        for &object in &self.unbounded {
            counters.exact_test();
            let Object::Shape(shape) = &self.objects[object as usize] else { continue };
            if let Some(hit) = shape.intersect(&record.ray) {
                let better = match best {
                    None => true,
                    Some(b) => hit.t < b.t || (hit.t == b.t && object < b.object),
                };
                if better {
                    record.ray.t_max = hit.t;
                    best = Some(WorldHit { t: hit.t, object, prim: 0, u: hit.u, v: hit.v });
                }
            }
        }
        best
    }

    /// Whether anything is hit within the ray's interval (shadow rays).
    pub fn any_hit<C: Counters>(&self, ray: &Ray, counters: &mut C) -> bool {
        if !ray.is_valid() {
            return false;
        }
        let unbounded_hit = self.unbounded.iter().any(|&object| {
            counters.exact_test();
            match &self.objects[object as usize] {
                Object::Shape(s) => s.intersect(ray).is_some(),
                Object::Mesh(_) | Object::Instance(_) => false,
            }
        });
        if unbounded_hit {
            return true;
        }
        let mut nested = C::default();
        let w = WatertightRay::new(ray);
        let hit = self.accel.any_hit(ray, counters, |prim, r| {
            let (object, local) = self.locate(prim);
            match &self.objects[object as usize] {
                Object::Shape(s) => s.intersect(r).is_some(),
                Object::Mesh(m) => m.intersect_with(local, r, &w).is_some(),
                Object::Instance(inst) => self.instance_any_hit(object, inst, r, &mut nested),
            }
        });
        counters.merge(&nested);
        hit
    }

    /// The unit geometric normal at the hit point `p` (outward for closed shapes, by winding for
    /// triangles, whatever side the ray came from).
    pub fn geometric_normal(&self, hit: &WorldHit, p: Vec3) -> Vec3 {
        match &self.objects[hit.object as usize] {
            Object::Shape(s) => s.normal(p, &PrimHit { t: hit.t, u: hit.u, v: hit.v }),
            Object::Mesh(m) => m.geometric_normal(hit.prim),
            Object::Instance(i) => i.normal_to_world(i.mesh().geometric_normal(hit.prim)),
        }
    }

    /// The unit normal for shading: interpolated vertex normals for meshes that have them, the
    /// geometric normal otherwise.
    pub fn shading_normal(&self, hit: &WorldHit, p: Vec3) -> Vec3 {
        match &self.objects[hit.object as usize] {
            Object::Mesh(m) => m.shading_normal(hit.prim, hit.u, hit.v),
            Object::Instance(i) => i.normal_to_world(i.mesh().shading_normal(hit.prim, hit.u, hit.v)),
            Object::Shape(_) => self.geometric_normal(hit, p),
        }
    }

    /// The hit point, moved back onto the surface where the shape allows it (spheres), which
    /// keeps secondary rays from starting inside or far off the surface.
    pub fn hit_point(&self, ray: &Ray, hit: &WorldHit) -> Vec3 {
        let p = ray.at(hit.t);
        match &self.objects[hit.object as usize] {
            Object::Shape(Shape::Sphere(s)) => s.project_to_surface(p),
            _ => p,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::{NoCount, WorkCounts};
    use crate::shapes::{Plane, Sphere, Triangle};

    fn sample() -> Vec<Object> {
        vec![
            Sphere::new(Vec3::new(0.0, 0.0, 5.0), 1.0).into(),
            Plane::new(Vec3::Y, Vec3::new(0.0, -1.0, 0.0)).unwrap().into(),
            Triangle::new(Vec3::new(-1.0, -1.0, 3.0), Vec3::new(1.0, -1.0, 3.0), Vec3::new(0.0, 1.0, 3.0)).into(),
            TriangleMesh::new(
                vec![Vec3::new(-5.0, -5.0, 10.0), Vec3::new(5.0, -5.0, 10.0), Vec3::new(0.0, 5.0, 10.0)],
                vec![[0, 1, 2]],
            )
            .unwrap()
            .into(),
        ]
    }

    #[test]
    fn closest_hit_names_the_object() {
        let w = World::build(sample(), AccelKind::None).unwrap();
        assert_eq!(w.primitive_count(), 3);
        let hit = w.closest_hit(&Ray::new(Vec3::ZERO, Vec3::Z), &mut NoCount).unwrap();
        assert_eq!((hit.object, hit.t), (2, 3.0));
        let hit = w.closest_hit(&Ray::new(Vec3::new(1.5, 0.0, 0.0), Vec3::Z), &mut NoCount).unwrap();
        assert_eq!((hit.object, hit.prim, hit.t), (3, 0, 10.0));
        let hit = w.closest_hit(&Ray::new(Vec3::new(3.0, 0.0, 0.0), -Vec3::Y), &mut NoCount).unwrap();
        assert_eq!((hit.object, hit.t), (1, 1.0));
        assert!(w.closest_hit(&Ray::new(Vec3::new(0.0, 0.0, 0.0), -Vec3::Z), &mut NoCount).is_none());
    }

    #[test]
    fn brute_force_counts_every_object_per_ray() {
        let w = World::build(sample(), AccelKind::None).unwrap();
        let mut c = WorkCounts::default();
        w.closest_hit(&Ray::new(Vec3::ZERO, Vec3::Z), &mut c);
        assert_eq!(c.exact_tests, 4);
    }

    #[test]
    fn any_hit_honours_the_interval() {
        let w = World::build(sample(), AccelKind::None).unwrap();
        assert!(w.any_hit(&Ray::segment(Vec3::ZERO, Vec3::Z, 0.0, 3.5), &mut NoCount));
        assert!(!w.any_hit(&Ray::segment(Vec3::ZERO, Vec3::Z, 0.0, 2.5), &mut NoCount));
        assert!(!w.any_hit(&Ray::new(Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 1.0)), &mut NoCount));
    }

    #[test]
    fn non_finite_shapes_are_refused() {
        let bad: Vec<Object> = vec![Sphere::new(Vec3::new(f32::NAN, 0.0, 0.0), 1.0).into()];
        assert!(matches!(World::build(bad, AccelKind::None), Err(WorldError::NonFiniteBounds { object: 0, .. })));
    }
}
