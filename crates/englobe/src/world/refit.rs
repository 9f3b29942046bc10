//! Meshes whose vertices move (a cloth, a character's skin, a deforming terrain): the world's
//! structures refitted instead of rebuilt, as Embree's `RTC_BUILD_QUALITY_REFIT` geometries are.
//! The triangles keep their numbers and vertices, so the tree keeps its shape and only its boxes
//! grow or shrink ([`TriangleBvh::refit_with`]); the report says how much the tree has loosened
//! (its SAH cost against the one it had when built), so a caller knows when to rebuild instead.
//!
//! A plain mesh's triangles live in the world's one [`TriangleBvh`] (the fast path), refitted
//! whole; a mesh placed by instances has its own bottom level, refitted, after which the instances
//! placing it get their new boxes and the structure above them is built again (as
//! [`World::move_instances`] does). The teaching structures hold every primitive in one structure,
//! which is built again.

use std::sync::Arc;

use glam::Vec3;

use super::bottom::BottomLevel;
use super::{Object, World, WorldError, accel_over_all};
use crate::accel::wide::RefitReport;
use crate::accel::{Accel, AccelKind};
use crate::shapes::{Instance, TriangleMesh};

impl World {
    /// Replaces plain mesh `object` by `mesh`, the same triangles (same vertex indices, in the same
    /// order) over moved vertices, and refits the structures to it. Queries afterwards answer as a
    /// world built over the moved mesh would, triangle for triangle.
    ///
    /// ```
    /// use englobe::{AccelKind, NoCount, Ray, TriangleMesh, Vec3, World};
    ///
    /// let tri = |z: f32| TriangleMesh::new(vec![Vec3::new(0.0, 0.0, z), Vec3::new(1.0, 0.0, z), Vec3::new(0.0, 1.0, z)], vec![[0, 1, 2]]);
    /// let mut world = World::build(vec![tri(0.0)?.into()], AccelKind::BvhWide)?;
    /// let ray = Ray::new(Vec3::new(0.2, 0.2, 5.0), -Vec3::Z);
    /// assert_eq!(world.closest_hit(&ray, &mut NoCount).map(|h| h.t), Some(5.0));
    /// let report = world.refit_mesh(0, tri(2.0)?)?;
    /// assert_eq!(world.closest_hit(&ray, &mut NoCount).map(|h| h.t), Some(3.0));
    /// assert!(!report.rebuilt);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn refit_mesh(&mut self, object: usize, mesh: TriangleMesh) -> Result<RefitReport, WorldError> {
        let Some(Object::Mesh(old)) = self.objects.get(object) else {
            return Err(WorldError::NotAMesh { object });
        };
        if old.triangles() != mesh.triangles() {
            return Err(WorldError::OtherTriangles { object });
        }
        self.objects[object] = Object::Mesh(Arc::new(mesh));
        let Some(triangles) = &mut self.triangles else {
            // A teaching structure over every primitive: built again.
            let boxes = self.all_bounds();
            self.accel = accel_over_all(self.kind, &self.objects, &self.prim_object, &self.object_first_prim, &boxes);
            return Ok(rebuilt(self.accel.stats().sah_cost));
        };
        let (objects, prim_object, first) = (&self.objects, &self.prim_object, &self.object_first_prim);
        let report = triangles.refit_with(prim_object.len(), |prim| {
            let object = prim_object[prim as usize];
            match &objects[object as usize] {
                Object::Mesh(m) => m.triangle(prim - first[object as usize]).vertices,
                _ => [Vec3::NAN; 3],
            }
        });
        // The count is the world's own and the topology was checked: a refit cannot be refused.
        Ok(report.expect("the world's own triangle count"))
    }

    /// Replaces the mesh that instances place, `placed` (the `Arc` they share), by `mesh`, the same
    /// triangles over moved vertices: its bottom level is refitted, every instance placing it moves
    /// onto the new mesh (keeping its transform), and the structure above the bottom levels is
    /// built again from the instances' new boxes. Keep `mesh` to name it in the next refit.
    pub fn refit_instanced_mesh(
        &mut self,
        placed: &Arc<TriangleMesh>,
        mesh: Arc<TriangleMesh>,
    ) -> Result<RefitReport, WorldError> {
        let Some(level) = self.bottom.iter().position(|b| Arc::ptr_eq(b.mesh(), placed)) else {
            return Err(WorldError::NotInstanced);
        };
        if placed.triangles() != mesh.triangles() {
            return Err(WorldError::OtherInstancedTriangles);
        }
        let report = self.bottom[level].refit(mesh.clone(), self.kind);
        for i in 0..self.objects.len() {
            if let Object::Instance(inst) = &self.objects[i]
                && Arc::ptr_eq(inst.mesh(), placed)
            {
                // The transform was accepted with the old mesh, whose vertices are finite like the
                // new one's: the instance cannot refuse it.
                let moved = Instance::new(mesh.clone(), *inst.to_world())
                    .map_err(|source| WorldError::Instance { object: i, source })?;
                self.objects[i] = Object::Instance(moved);
            }
        }
        self.rebuild_top();
        Ok(report)
    }
}

/// The report of a structure built again.
fn rebuilt(sah_cost: Option<f32>) -> RefitReport {
    let cost = sah_cost.unwrap_or(0.0);
    RefitReport { rebuilt: true, sah_cost: cost, built_sah_cost: cost }
}

impl BottomLevel {
    /// Moves the level onto `mesh` (the same triangles over moved vertices): the fast structure is
    /// refitted, a teaching structure built again.
    pub(super) fn refit(&mut self, mesh: Arc<TriangleMesh>, kind: AccelKind) -> RefitReport {
        match self.triangle_bvh_mut() {
            Some(t) => {
                let report = t.refit(&mesh).expect("the same triangle count");
                self.set_mesh(mesh);
                report
            }
            None => {
                *self = BottomLevel::build(mesh, kind);
                rebuilt(self.stats().sah_cost)
            }
        }
    }
}
