//! The bottom level of the two-level hierarchy (Wald, Benthin and Slusallek 2003, "A Simple and
//! Practical Method for Interactive Ray Tracing of Dynamic Scenes"): one structure per distinct
//! instanced mesh, in the mesh's own space, shared by all its instances. On the fast path
//! ([`AccelKind::BvhWide`]) it is a [`TriangleBvh`], triangles in SIMD blocks in its leaves; the
//! teaching structures build one of their own kind over the triangles' boxes.
//!
//! A world query sees an instance as one primitive. Its closure returns the hit's `t`, `u` and `v`
//! but has no room for the triangle that was hit, so the world keeps, beside the structure's own
//! record, the best instance hit under the same rule as [`crate::accel::HitRecord::offer`]
//! (closer, or as close with a lower primitive number). Every structure offers its candidates
//! through that rule, so when the structure's answer is an instance, the record names the same
//! instance, at the same `t`, and gives its triangle.

use std::collections::HashMap;
use std::sync::Arc;

use super::Object;
use crate::accel::{Accel, AccelKind, AnyAccel, Counters, Hit, HitFilter, NoFilter, StructureStats, TriangleBvh};
use crate::shapes::{TriangleMesh, WatertightRay, clip_triangle};
use crate::{Aabb, Ray};

/// The structure of a [`BottomLevel`].
#[derive(Clone, Debug)]
enum BottomAccel {
    /// The fast path: triangles stored in the leaves.
    Triangles(TriangleBvh),
    /// A structure of the world's kind, its leaves tested through the mesh.
    Generic(AnyAccel),
}

/// A structure over the triangles of one mesh, in the mesh's own space.
#[derive(Clone, Debug)]
pub struct BottomLevel {
    mesh: Arc<TriangleMesh>,
    accel: BottomAccel,
}

impl BottomLevel {
    /// The structure `kind` over the triangles of `mesh`: a [`TriangleBvh`] for
    /// [`AccelKind::BvhWide`], the structure `kind` over the triangles' boxes otherwise.
    pub fn build(mesh: Arc<TriangleMesh>, kind: AccelKind) -> Self {
        let accel = if kind == AccelKind::BvhWide {
            BottomAccel::Triangles(TriangleBvh::build(&mesh))
        } else {
            let boxes: Vec<_> = (0..mesh.len() as u32).map(|t| mesh.triangle_bounds(t)).collect();
            let clip = |t: u32, cell: &Aabb| clip_triangle(mesh.triangle(t).vertices, cell);
            BottomAccel::Generic(AnyAccel::build_with_clipper(kind, &boxes, &clip))
        };
        BottomLevel { accel, mesh }
    }

    /// The mesh.
    pub fn mesh(&self) -> &Arc<TriangleMesh> {
        &self.mesh
    }

    /// Size and shape of the structure.
    pub fn stats(&self) -> StructureStats {
        match &self.accel {
            BottomAccel::Triangles(t) => t.stats(),
            BottomAccel::Generic(a) => a.stats(),
        }
    }

    /// The fast structure, if this level has one.
    pub fn triangle_bvh(&self) -> Option<&TriangleBvh> {
        match &self.accel {
            BottomAccel::Triangles(t) => Some(t),
            BottomAccel::Generic(_) => None,
        }
    }

    /// The fast structure, to refit.
    pub(super) fn triangle_bvh_mut(&mut self) -> Option<&mut TriangleBvh> {
        match &mut self.accel {
            BottomAccel::Triangles(t) => Some(t),
            BottomAccel::Generic(_) => None,
        }
    }

    /// Puts `mesh` in place of the mesh, once the structure fits it.
    pub(super) fn set_mesh(&mut self, mesh: Arc<TriangleMesh>) {
        self.mesh = mesh;
    }

    /// The closest triangle hit by `ray`, given in the mesh's space: `prim` is the triangle.
    #[inline]
    pub fn closest_hit<C: Counters>(&self, ray: &Ray, counters: &mut C) -> Option<Hit> {
        self.closest_hit_filtered(ray, counters, NoFilter)
    }

    /// Whether `ray`, given in the mesh's space, hits a triangle within its interval.
    #[inline]
    pub fn any_hit<C: Counters>(&self, ray: &Ray, counters: &mut C) -> bool {
        self.any_hit_filtered(ray, counters, NoFilter)
    }

    /// [`BottomLevel::closest_hit`] among the hits `filter` accepts.
    #[inline]
    pub fn closest_hit_filtered<C: Counters, F: HitFilter<Hit>>(
        &self,
        ray: &Ray,
        counters: &mut C,
        mut filter: F,
    ) -> Option<Hit> {
        match &self.accel {
            BottomAccel::Triangles(t) => t.closest_hit_filtered(ray, counters, filter),
            BottomAccel::Generic(accel) => {
                // The mesh's box first: brute force has no root box of its own to skip the mesh with.
                counters.box_tests(1);
                accel.bounds().intersect(ray)?;
                let w = WatertightRay::new(ray);
                accel.closest_hit(ray, counters, |tri, r| {
                    let h = self.mesh.intersect_with(tri, r, &w)?;
                    (F::ACCEPTS_ALL || filter.accept(&Hit { t: h.t, prim: tri, u: h.u, v: h.v })).then_some(h)
                })
            }
        }
    }

    /// [`BottomLevel::any_hit`] counting only the hits `filter` accepts.
    #[inline]
    pub fn any_hit_filtered<C: Counters, F: HitFilter<Hit>>(&self, ray: &Ray, counters: &mut C, mut filter: F) -> bool {
        match &self.accel {
            BottomAccel::Triangles(t) => t.any_hit_filtered(ray, counters, filter),
            BottomAccel::Generic(accel) => {
                counters.box_tests(1);
                if accel.bounds().intersect(ray).is_none() {
                    return false;
                }
                let w = WatertightRay::new(ray);
                accel.any_hit(ray, counters, |tri, r| {
                    self.mesh
                        .intersect_with(tri, r, &w)
                        .is_some_and(|h| F::ACCEPTS_ALL || filter.accept(&Hit { t: h.t, prim: tri, u: h.u, v: h.v }))
                })
            }
        }
    }
}

/// One bottom-level structure per distinct mesh (by `Arc` identity) among the instances, and for
/// every object the index of its structure ([`NOT_NESTED`] for objects that are not instances).
/// Distinct meshes are built in parallel where the `parallel` feature allows.
pub(super) fn build_bottom_levels(objects: &[Object], kind: AccelKind) -> (Vec<BottomLevel>, Vec<u32>) {
    let mut meshes: Vec<Arc<TriangleMesh>> = Vec::new();
    let mut by_mesh: HashMap<*const TriangleMesh, u32> = HashMap::new();
    let object_bottom = objects
        .iter()
        .map(|o| match o {
            Object::Instance(inst) => *by_mesh.entry(Arc::as_ptr(inst.mesh())).or_insert_with(|| {
                meshes.push(inst.mesh().clone());
                (meshes.len() - 1) as u32
            }),
            _ => NOT_NESTED,
        })
        .collect();
    #[cfg(feature = "parallel")]
    let bottom = {
        use rayon::prelude::*;
        meshes.into_par_iter().map(|m| BottomLevel::build(m, kind)).collect()
    };
    #[cfg(not(feature = "parallel"))]
    let bottom = meshes.into_iter().map(|m| BottomLevel::build(m, kind)).collect();
    (bottom, object_bottom)
}

/// The bottom level of an object that is not an instance.
pub(super) const NOT_NESTED: u32 = u32::MAX;

/// The best instance hit offered during one world query: its world primitive, `t` and triangle.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct ClosestInstance {
    best: Option<(u32, f32, u32)>,
}

impl ClosestInstance {
    /// Keeps the hit `hit` on the world primitive `prim` if it beats the current one under the
    /// rule of `HitRecord::offer`.
    #[inline(always)]
    pub(super) fn offer(&mut self, prim: u32, hit: &Hit) {
        let better = match self.best {
            None => true,
            Some((p, t, _)) => hit.t < t || (hit.t == t && prim < p),
        };
        if better {
            self.best = Some((prim, hit.t, hit.prim));
        }
    }

    /// The triangle of the instance hit kept for `prim` at `t`, if that is the kept one.
    pub(super) fn triangle(&self, prim: u32, t: f32) -> Option<u32> {
        self.best.filter(|&(p, bt, _)| p == prim && bt == t).map(|(_, _, tri)| tri)
    }
}
