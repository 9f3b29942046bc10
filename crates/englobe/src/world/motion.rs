//! Scenes that move: instances placed anew every frame. The meshes they place do not change, so
//! their bottom-level structures (shared by every instance of a mesh) are kept, and only the
//! structure over the instances and shapes is built again, from the instances' new boxes: the
//! two-level design's reason to be (Wald, Benthin and Slusallek 2003, "Distributed Interactive
//! Ray Tracing of Dynamic Scenes"; Embree's instanced scenes commit the same way).
//!
//! The rebuilt world is the one [`World::build`] gives for the moved objects, structure for
//! structure, so its answers are the same bit for bit (the builders are deterministic).

use glam::Affine3A;

use super::{Object, World, WorldError, accel_over_all};
use crate::Aabb;
use crate::accel::{AccelKind, AnyAccel};
use crate::shapes::{Bounded, Instance};

impl World {
    /// Places each instance `object` at its new transform (`to_world`, as [`Instance::new`]
    /// takes it), then rebuilds the structure above the bottom levels. With the fast path
    /// ([`AccelKind::BvhWide`]) that is the wide BVH over the instances and shapes alone: the
    /// plain meshes' triangles and every instanced mesh's structure are kept. The teaching
    /// structures hold every primitive in one structure, which is rebuilt whole.
    ///
    /// Nothing changes if any entry is refused (not an instance, or a transform the instance
    /// refuses). Queries take `&self`, so they cannot run during the update.
    ///
    /// ```
    /// use std::sync::Arc;
    /// use englobe::{AccelKind, Affine3A, Instance, NoCount, Ray, TriangleMesh, Vec3, World};
    ///
    /// let tri = Arc::new(TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]])?);
    /// let mut world = World::build(vec![Instance::new(tri, Affine3A::IDENTITY)?.into()], AccelKind::BvhWide)?;
    /// let ray = Ray::new(Vec3::new(0.2, 0.2, 5.0), -Vec3::Z);
    /// assert_eq!(world.closest_hit(&ray, &mut NoCount).map(|h| h.t), Some(5.0));
    /// world.move_instances(&[(0, Affine3A::from_translation(Vec3::new(0.0, 0.0, 1.0)))])?;
    /// assert_eq!(world.closest_hit(&ray, &mut NoCount).map(|h| h.t), Some(4.0));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn move_instances(&mut self, moves: &[(usize, Affine3A)]) -> Result<(), WorldError> {
        let mut placed = Vec::with_capacity(moves.len());
        for &(object, to_world) in moves {
            let Some(Object::Instance(old)) = self.objects.get(object) else {
                return Err(WorldError::NotAnInstance { object });
            };
            let moved = Instance::new(old.mesh().clone(), to_world)
                .map_err(|source| WorldError::Instance { object, source })?;
            placed.push((object, moved));
        }
        for (object, moved) in placed {
            self.objects[object] = Object::Instance(moved);
        }
        self.rebuild_top();
        Ok(())
    }

    /// Builds the structure above the bottom levels again, from the objects as they are now.
    pub(super) fn rebuild_top(&mut self) {
        self.accel = match (&self.accel_prims, self.kind) {
            // The fast path with plain meshes: the structure over shapes and instances only.
            (Some(prims), _) => {
                let boxes: Vec<Aabb> = prims.iter().map(|&p| self.prim_bounds(p)).collect();
                AnyAccel::build(self.kind, &boxes)
            }
            // The fast path without plain meshes: one wide BVH over every primitive.
            (None, AccelKind::BvhWide) => AnyAccel::build(self.kind, &self.all_bounds()),
            (None, kind) => {
                let boxes = self.all_bounds();
                accel_over_all(kind, &self.objects, &self.prim_object, &self.object_first_prim, &boxes)
            }
        };
    }

    /// The box of primitive `prim`, as [`World::build`] computes it.
    fn prim_bounds(&self, prim: u32) -> Aabb {
        let (object, local) = self.locate(prim);
        match &self.objects[object as usize] {
            Object::Shape(s) => s.bounds(),
            Object::Mesh(m) => m.triangle_bounds(local),
            Object::Instance(i) => i.bounds(),
        }
    }

    /// The boxes of every bounded primitive, by primitive number.
    pub(super) fn all_bounds(&self) -> Vec<Aabb> {
        (0..self.prim_object.len() as u32).map(|p| self.prim_bounds(p)).collect()
    }
}
