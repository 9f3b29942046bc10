//! A world: a list of objects (shapes, meshes and mesh instances) with acceleration structures
//! over their bounded primitives. It answers closest-hit and any-hit queries in terms of objects,
//! which is what a renderer or any other user of ray queries needs.
//!
//! Every bounded primitive (a sphere, a box, one triangle of a mesh, one whole instance) gets a
//! number in the order the objects were given. Unbounded shapes (planes) stay beside the
//! structures and are tested after them, as every production ray tracer does. Instances make a
//! two-level hierarchy (Wald, Benthin and Slusallek 2003): a structure over the instances' boxes
//! on top, one structure per distinct instanced mesh below ([`BottomLevel`]).
//!
//! What the kind builds:
//!
//! * [`AccelKind::BvhWide`], the fast path, is eight-wide at both levels, as Embree builds a
//!   scene: the triangles of every plain mesh in one [`TriangleBvh`] (triangles in SIMD blocks in
//!   its leaves, numbered as above, so one query covers them all with no overlap between
//!   meshes); the shapes and instances in a [`crate::WideBvh`] whose leaves call the exact test;
//!   every instanced mesh a [`TriangleBvh`] of its own. A world without a plain mesh has the wide
//!   BVH alone, over every primitive.
//! * The teaching structures are measured as the seed report measured its own: one structure of
//!   the kind over every primitive (each triangle of a plain mesh among them), and instanced
//!   meshes below in a structure of the same kind. Structures that split primitives across cells
//!   (the kd-tree) get each triangle's exact part in a cell ([`clip_triangle`]), and the box's
//!   part for other shapes.
//!
//! Every kind gives the same answers, bit for bit: a triangle's test is the same watertight test
//! everywhere, and ties at equal `t` go to the lower number at every level.
//!
//! Worlds move without being built again: instances are placed anew (`motion.rs`) and meshes
//! deform (`refit.rs`), the structures refitted or rebuilt only above what changed.

use glam::Vec3;

mod batch;
mod bottom;
mod motion;
mod object;
mod packet;
mod planes;
mod proximity;
mod query;
mod refit;

use crate::PrimHit;
use crate::accel::{Accel, AccelKind, AnyAccel, MAX_PRIMITIVES, StructureStats, TriangleBvh};
use crate::shapes::{Bounded, Intersect, Plane, Shape, clip_triangle};
use crate::{Aabb, Ray};

pub use bottom::BottomLevel;
pub use object::Object;

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
    /// [`World::move_instances`] was asked to move an object that is not an instance.
    #[error("object {object} is not an instance: only instances move")]
    NotAnInstance {
        /// Object index.
        object: usize,
    },
    /// [`World::refit_mesh`] was asked to refit an object that is not a plain mesh.
    #[error("object {object} is not a mesh: only meshes are refitted")]
    NotAMesh {
        /// Object index.
        object: usize,
    },
    /// [`World::refit_mesh`] was given a mesh whose triangles are not the object's.
    #[error("object {object}: the new mesh's triangles differ from the old one's (a refit moves vertices only)")]
    OtherTriangles {
        /// Object index.
        object: usize,
    },
    /// [`World::refit_instanced_mesh`] was given a mesh no instance of the world places.
    #[error("no instance of the world places this mesh")]
    NotInstanced,
    /// [`World::refit_instanced_mesh`] was given a mesh whose triangles are not the placed one's.
    #[error("the new mesh's triangles differ from the instanced one's (a refit moves vertices only)")]
    OtherInstancedTriangles,
    /// [`World::move_instances`] was given a transform the instance refuses.
    #[error("object {object}: {source}")]
    Instance {
        /// Object index.
        object: usize,
        /// Why.
        #[source]
        source: crate::shapes::InstanceError,
    },
}

/// The structure `kind` over every primitive (the teaching structures hold them all in one), with
/// split clipping: a triangle's exact part in a cell, any other shape's box's part.
fn accel_over_all(
    kind: AccelKind,
    objects: &[Object],
    prim_object: &[u32],
    object_first_prim: &[u32],
    boxes: &[Aabb],
) -> AnyAccel {
    let clip = |prim: u32, cell: &Aabb| {
        let object = prim_object[prim as usize];
        match &objects[object as usize] {
            Object::Mesh(m) => clip_triangle(m.triangle(prim - object_first_prim[object as usize]).vertices, cell),
            Object::Shape(Shape::Triangle(t)) => clip_triangle(t.vertices, cell),
            _ => boxes[prim as usize].intersection(cell),
        }
    };
    AnyAccel::build_with_clipper(kind, boxes, &clip)
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

/// The closest point of a world's meshes to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldPoint {
    /// The mesh object it lies on.
    pub object: u32,
    /// Its triangle within that mesh.
    pub prim: u32,
    /// The point.
    pub point: Vec3,
    /// Its distance to the query point.
    pub distance: f32,
}

/// Objects plus acceleration structures over their bounded primitives.
#[derive(Clone, Debug)]
pub struct World {
    objects: Vec<Object>,
    /// For each primitive number, its object.
    prim_object: Vec<u32>,
    /// For each object, the number of its first primitive.
    object_first_prim: Vec<u32>,
    /// The unbounded shapes (planes, the only kind), tested beside the structures: each with its
    /// object number, held here by value so that every query tests them without a lookup or a
    /// dispatch on the shape's kind.
    unbounded: Vec<(u32, Plane)>,
    kind: AccelKind,
    /// The structure over the primitives that are not in [`World::triangles`].
    accel: AnyAccel,
    /// The primitive number of each of `accel`'s primitives, where they are not all of them in
    /// order (the fast path, whose `accel` holds only shapes and instances).
    accel_prims: Option<Vec<u32>>,
    /// The fast path, if the world has a plain mesh: every triangle of every plain mesh, by
    /// primitive number.
    triangles: Option<TriangleBvh>,
    /// Bottom-level structures, one per distinct instanced mesh, shared by its instances.
    bottom: Vec<BottomLevel>,
    /// For each object, the index of its bottom-level structure (instances only).
    object_bottom: Vec<u32>,
}

impl World {
    /// Builds a world over `objects` with the structure `kind` (see the [module](self) for what
    /// each kind builds). Instances of the same mesh (the same `Arc`) share one bottom-level
    /// structure.
    ///
    /// ```
    /// use englobe::{AccelKind, NoCount, Ray, Sphere, TriangleMesh, Vec3, World};
    ///
    /// let floor = TriangleMesh::new(
    ///     vec![Vec3::new(-5.0, 0.0, -5.0), Vec3::new(5.0, 0.0, -5.0), Vec3::new(0.0, 0.0, 5.0)],
    ///     vec![[0, 1, 2]],
    /// )?;
    /// let world = World::build(vec![floor.into(), Sphere::new(Vec3::Y, 0.5).into()], AccelKind::BvhWide)?;
    /// let hit = world.closest_hit(&Ray::new(Vec3::new(0.0, 3.0, 0.0), -Vec3::Y), &mut NoCount).expect("a hit");
    /// assert_eq!((hit.object, hit.t), (1, 1.5));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
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
                Object::Shape(Shape::Plane(p)) => unbounded.push((i as u32, *p)),
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
        let (accel, accel_prims, triangles) = if kind == AccelKind::BvhWide {
            let in_mesh = |prim: u32| matches!(objects[prim_object[prim as usize] as usize], Object::Mesh(_));
            let others: Vec<u32> = (0..total as u32).filter(|&p| !in_mesh(p)).collect();
            if others.len() == total {
                // No mesh: one wide BVH over every primitive, in their own order.
                (AnyAccel::build(kind, &boxes), None, None)
            } else {
                // Primitives that are not mesh triangles get no triangle: the builder leaves out
                // triangles with non-finite corners.
                let triangles = TriangleBvh::build_with(
                    total,
                    |prim| {
                        let object = prim_object[prim as usize];
                        match &objects[object as usize] {
                            Object::Mesh(m) => m.triangle(prim - object_first_prim[object as usize]).vertices,
                            _ => [Vec3::NAN; 3],
                        }
                    },
                    Default::default(),
                );
                let other_boxes: Vec<Aabb> = others.iter().map(|&p| boxes[p as usize]).collect();
                (AnyAccel::build(kind, &other_boxes), Some(others), Some(triangles))
            }
        } else {
            (accel_over_all(kind, &objects, &prim_object, &object_first_prim, &boxes), None, None)
        };
        drop(boxes);
        let (bottom, object_bottom) = bottom::build_bottom_levels(&objects, kind);
        Ok(World {
            objects,
            prim_object,
            object_first_prim,
            unbounded,
            kind,
            accel,
            accel_prims,
            triangles,
            bottom,
            object_bottom,
        })
    }

    /// The objects, in the order given.
    pub fn objects(&self) -> &[Object] {
        &self.objects
    }

    /// The structure's kind.
    pub fn accel_kind(&self) -> AccelKind {
        self.kind
    }

    /// The structure over the bounded primitives: all of them, or on the fast path those that
    /// are not triangles of a plain mesh (see [`World::triangles`]).
    pub fn accel(&self) -> &AnyAccel {
        &self.accel
    }

    /// The fast path's structure over every triangle of every plain mesh (`None` for the
    /// teaching structures and for a world without a plain mesh). Its triangle numbers are the
    /// world's primitive numbers.
    pub fn triangles(&self) -> Option<&TriangleBvh> {
        self.triangles.as_ref()
    }

    /// Size and shape of the structures over the world's primitives (the instanced meshes'
    /// structures are apart: see [`World::bottom_levels`]). On the fast path, the triangles' and
    /// the other primitives' structures summed: counts and bytes added, the deeper depth, and no
    /// SAH cost.
    pub fn stats(&self) -> StructureStats {
        let top = self.accel.stats();
        let Some(triangles) = &self.triangles else { return top };
        let t = triangles.stats();
        let mut leaf_sizes = top.leaf_sizes;
        for (a, b) in leaf_sizes.iter_mut().zip(t.leaf_sizes) {
            *a += b;
        }
        StructureStats {
            nodes: top.nodes + t.nodes,
            leaves: top.leaves + t.leaves,
            depth: top.depth.max(t.depth),
            prim_refs: top.prim_refs + t.prim_refs,
            memory_bytes: top.memory_bytes + t.memory_bytes,
            sah_cost: None,
            leaf_sizes,
        }
    }

    /// The bottom-level structures, one per distinct instanced mesh.
    pub fn bottom_levels(&self) -> &[BottomLevel] {
        &self.bottom
    }

    /// Triangles in the picture, every instance counting its mesh's.
    pub fn triangle_count(&self) -> usize {
        self.objects.iter().map(Object::triangle_count).sum()
    }

    /// Number of bounded primitives: shapes, instances and every triangle of a plain mesh
    /// (unbounded shapes not included), whichever structure holds them.
    pub fn primitive_count(&self) -> usize {
        self.prim_object.len()
    }

    /// Box around the bounded primitives.
    pub fn bounds(&self) -> Aabb {
        let b = self.accel.bounds();
        self.triangles.as_ref().map_or(b, |t| b.union(&t.bounds()))
    }

    /// The object of primitive `prim`, and the primitive's index within it.
    #[inline(always)]
    fn locate(&self, prim: u32) -> (u32, u32) {
        let object = self.prim_object[prim as usize];
        (object, prim - self.object_first_prim[object as usize])
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

    /// Both normals at `hit`, `(geometric, shading)`: the same numbers as
    /// [`World::geometric_normal`] and [`World::shading_normal`], the object looked up once and a
    /// flat surface's normal computed once (a renderer needs both at every hit).
    #[inline]
    pub fn normals(&self, hit: &WorldHit, p: Vec3) -> (Vec3, Vec3) {
        match &self.objects[hit.object as usize] {
            Object::Shape(s) => {
                let n = s.normal(p, &PrimHit { t: hit.t, u: hit.u, v: hit.v });
                (n, n)
            }
            Object::Mesh(m) => {
                let (geometric, shading) = m.normals_at(hit.prim, hit.u, hit.v);
                (geometric, shading.unwrap_or(geometric))
            }
            Object::Instance(i) => {
                let (geometric, shading) = i.mesh().normals_at(hit.prim, hit.u, hit.v);
                let geometric = i.normal_to_world(geometric);
                (geometric, shading.map_or(geometric, |n| i.normal_to_world(n)))
            }
        }
    }

    /// Starts loading into the cache what [`World::geometric_normal`] and
    /// [`World::shading_normal`] will read for `hit` (a mesh triangle's vertices and normals).
    /// A renderer with several hits to shade calls it for all of them first, so that their cache
    /// misses overlap rather than come one after the other. Only a hint: it changes no answer.
    #[inline]
    pub fn prefetch_shading(&self, hit: &WorldHit) {
        match self.objects.get(hit.object as usize) {
            Some(Object::Mesh(m)) => m.prefetch_triangle(hit.prim),
            Some(Object::Instance(i)) => i.mesh().prefetch_triangle(hit.prim),
            Some(Object::Shape(_)) | None => {}
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
    use crate::shapes::TriangleMesh;
    use crate::shapes::{Instance, Plane, Sphere, Triangle};
    use glam::Affine3A;
    use std::sync::Arc;

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

    /// Both normals in one look-up are the two asked apart, on a shape, a flat mesh, a smooth
    /// mesh (its normals cancelling out at one point) and their instances.
    #[test]
    fn both_normals_at_once_are_the_two_asked_apart() {
        let quad = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let flat = Arc::new(TriangleMesh::new(quad.clone(), vec![[0, 1, 2], [0, 2, 3]]).unwrap());
        let normals = vec![Vec3::new(0.3, 0.0, 1.0), Vec3::new(-0.3, 0.0, -1.0), Vec3::Z, Vec3::new(0.0, 0.5, 1.0)];
        let smooth =
            Arc::new(TriangleMesh::new(quad, vec![[0, 1, 2], [0, 2, 3]]).unwrap().with_normals(normals).unwrap());
        let turn = Affine3A::from_scale_rotation_translation(
            Vec3::new(1.0, -2.0, 0.5),
            glam::Quat::from_rotation_y(0.7),
            Vec3::X,
        );
        let mut objects = sample();
        objects.push(Object::Mesh(flat.clone()));
        objects.push(Object::Mesh(smooth.clone()));
        objects.push(Instance::new(flat, turn).unwrap().into());
        objects.push(Instance::new(smooth, turn).unwrap().into());
        let world = World::build(objects, AccelKind::BvhWide).unwrap();
        let p = Vec3::new(0.2, 0.3, 0.0);
        for object in 0..world.objects().len() as u32 {
            for (prim, u, v) in [(0, 0.2, 0.3), (1, 0.5, 0.5), (0, 0.5, 0.0)] {
                let hit = WorldHit { t: 1.0, object, prim: if object < 4 { 0 } else { prim }, u, v };
                let apart = (world.geometric_normal(&hit, p), world.shading_normal(&hit, p));
                assert_eq!(world.normals(&hit, p), apart, "object {object}, {hit:?}");
            }
        }
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
