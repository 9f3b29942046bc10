//! The bottom level of the two-level hierarchy (Wald, Benthin and Slusallek 2003, "A Simple and
//! Practical Method for Interactive Ray Tracing of Dynamic Scenes"): one structure per distinct
//! instanced mesh, shared by all its instances, and the queries that move a ray into an
//! instance's space and trace it there.
//!
//! A world query sees an instance as one primitive. Its closure returns the hit's `t`, `u` and `v`
//! but has no room for the triangle that was hit, so the world keeps, beside the structure's own
//! record, the best instance hit under the same rule as [`crate::accel::HitRecord::offer`]
//! (closer, or as close with a lower primitive index). Every structure offers its candidates
//! through that rule, so when the structure's answer is an instance, the record names the same
//! instance, at the same `t`, and gives its triangle.

use std::collections::HashMap;
use std::sync::Arc;

use super::{Object, World};
use crate::accel::{Accel, AccelKind, AnyAccel, Counters, Hit, StructureStats};
use crate::shapes::{Instance, TriangleMesh, WatertightRay, clip_triangle};

/// A structure over the triangles of one mesh, in the mesh's own space.
#[derive(Clone, Debug)]
pub struct BottomLevel {
    mesh: Arc<TriangleMesh>,
    accel: AnyAccel,
}

impl BottomLevel {
    /// The structure `kind` over the triangles of `mesh`.
    pub fn build(mesh: Arc<TriangleMesh>, kind: AccelKind) -> Self {
        let boxes: Vec<_> = (0..mesh.len() as u32).map(|t| mesh.triangle_bounds(t)).collect();
        let clip = |t: u32, cell: &crate::Aabb| clip_triangle(mesh.triangle(t).vertices, cell);
        let accel = AnyAccel::build_with_clipper(kind, &boxes, &clip);
        BottomLevel { accel, mesh }
    }

    /// The mesh.
    pub fn mesh(&self) -> &Arc<TriangleMesh> {
        &self.mesh
    }

    /// Size and shape of the structure.
    pub fn stats(&self) -> StructureStats {
        self.accel.stats()
    }
}

/// One bottom-level structure per distinct mesh (by `Arc` identity) among the instances, and for
/// every object the index of its structure (`u32::MAX` for objects that are not instances).
pub(super) fn build_bottom_levels(objects: &[Object], kind: AccelKind) -> (Vec<BottomLevel>, Vec<u32>) {
    let mut bottom = Vec::new();
    let mut by_mesh: HashMap<*const TriangleMesh, u32> = HashMap::new();
    let object_bottom = objects
        .iter()
        .map(|o| match o {
            Object::Instance(inst) => *by_mesh.entry(Arc::as_ptr(inst.mesh())).or_insert_with(|| {
                bottom.push(BottomLevel::build(inst.mesh().clone(), kind));
                (bottom.len() - 1) as u32
            }),
            _ => u32::MAX,
        })
        .collect();
    (bottom, object_bottom)
}

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

impl World {
    /// The closest hit of `ray` (in world space) with the mesh of `inst`, object `object`: `prim`
    /// of the answer is the triangle, `t` is the world ray's parameter.
    #[inline]
    pub(super) fn instance_closest_hit<C: Counters>(
        &self,
        object: u32,
        inst: &Instance,
        ray: &crate::Ray,
        counters: &mut C,
    ) -> Option<Hit> {
        let bottom = &self.bottom[self.object_bottom[object as usize] as usize];
        let local = inst.local_ray(ray);
        // The mesh's box first: brute force has no root box of its own to skip the mesh with.
        counters.box_tests(1);
        bottom.accel.bounds().intersect(&local)?;
        let mesh = &bottom.mesh;
        let w = WatertightRay::new(&local);
        bottom.accel.closest_hit(&local, counters, |tri, r| mesh.intersect_with(tri, r, &w))
    }

    /// Whether `ray` hits the mesh of `inst` within its interval.
    #[inline]
    pub(super) fn instance_any_hit<C: Counters>(
        &self,
        object: u32,
        inst: &Instance,
        ray: &crate::Ray,
        counters: &mut C,
    ) -> bool {
        let bottom = &self.bottom[self.object_bottom[object as usize] as usize];
        let local = inst.local_ray(ray);
        counters.box_tests(1);
        if bottom.accel.bounds().intersect(&local).is_none() {
            return false;
        }
        let mesh = &bottom.mesh;
        let w = WatertightRay::new(&local);
        bottom.accel.any_hit(&local, counters, |tri, r| mesh.intersect_with(tri, r, &w).is_some())
    }
}

#[cfg(test)]
mod tests {
    use glam::{Affine3A, Quat, Vec3};
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::*;
    use crate::accel::{NoCount, WorkCounts};
    use crate::shapes::Sphere;
    use crate::{Ray, WorldHit};

    fn cube() -> Arc<TriangleMesh> {
        let p = (0..8).map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32)).collect();
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let tris = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
        Arc::new(TriangleMesh::new(p, tris).unwrap())
    }

    fn baked(mesh: &TriangleMesh, m: &Affine3A) -> TriangleMesh {
        TriangleMesh::new(mesh.positions().iter().map(|&p| m.transform_point3(p)).collect(), mesh.triangles().to_vec())
            .unwrap()
    }

    fn placements() -> Vec<Affine3A> {
        (0..5)
            .map(|i| {
                Affine3A::from_scale_rotation_translation(
                    Vec3::new(1.0 + i as f32 * 0.5, 1.0, 2.0),
                    Quat::from_euler(glam::EulerRot::XYZ, 0.3 * i as f32, 0.7, -0.2 * i as f32),
                    Vec3::new(i as f32 * 3.0 - 6.0, 0.5 * i as f32, 10.0),
                )
            })
            .collect()
    }

    #[test]
    fn instances_share_one_bottom_level_structure() {
        let mesh = cube();
        let other = cube();
        let mut objects: Vec<Object> =
            placements().iter().map(|m| Instance::new(mesh.clone(), *m).unwrap().into()).collect();
        objects.push(Instance::new(other, Affine3A::IDENTITY).unwrap().into());
        let w = World::build(objects, AccelKind::None).unwrap();
        assert_eq!(w.bottom_levels().len(), 2);
        assert_eq!(w.primitive_count(), 6);
        assert_eq!(w.triangle_count(), 72);
        assert_eq!(Arc::strong_count(&mesh), 6 + 1, "five instances, one structure, and this handle");
    }

    #[test]
    fn instances_answer_like_the_same_meshes_baked_into_the_world() {
        let mesh = cube();
        let mut instanced: Vec<Object> = vec![Sphere::new(Vec3::new(0.0, 0.0, 14.0), 1.5).into()];
        let mut flat = instanced.clone();
        for m in placements() {
            instanced.push(Instance::new(mesh.clone(), m).unwrap().into());
            flat.push(baked(&mesh, &m).into());
        }
        let wi = World::build(instanced, AccelKind::None).unwrap();
        let wf = World::build(flat, AccelKind::None).unwrap();
        let mut rng = Pcg32::seed_from_u64(0x2545_f491);
        let mut next = move || rng.random::<f32>();
        let (mut hits, mut counts) = (0, WorkCounts::default());
        for _ in 0..4000 {
            let target = Vec3::new(next() * 16.0 - 8.0, next() * 6.0 - 2.0, 8.0 + next() * 8.0);
            let ray = Ray::new(Vec3::new(0.0, 1.0, -5.0), target - Vec3::new(0.0, 1.0, -5.0));
            let a = wi.closest_hit(&ray, &mut counts);
            let b = wf.closest_hit(&ray, &mut NoCount);
            assert_eq!(a.is_some(), b.is_some(), "{ray:?}");
            assert_eq!(wi.any_hit(&ray, &mut NoCount), wf.any_hit(&ray, &mut NoCount));
            let (Some(a), Some(b)) = (a, b) else { continue };
            hits += 1;
            let p = wi.hit_point(&ray, &a);
            assert!((a.t - b.t).abs() <= 1e-4 * b.t, "{a:?} vs {b:?}");
            assert_eq!((a.object, a.prim), (b.object, b.prim));
            let (na, nb) = (wi.geometric_normal(&a, p), wf.geometric_normal(&b, p));
            assert!((na - nb).length() < 1e-4, "{na} vs {nb}");
            assert!((wi.shading_normal(&a, p) - wf.shading_normal(&b, p)).length() < 1e-4);
        }
        assert!(hits > 1000, "only {hits} hits: the test scene is off camera");
        // Brute force over 6 world primitives, plus a mesh box and the mesh's 12 triangles for
        // every instance whose box the ray enters.
        assert!(counts.exact_tests >= 4000 * 6 && counts.box_tests >= 4000 * 5, "{counts:?}");
        assert_eq!((counts.exact_tests - 4000 * 6) % 12, 0, "{counts:?}");
    }

    #[test]
    fn the_closest_of_overlapping_instances_wins_with_its_own_triangle() {
        let mesh = cube();
        let near = Affine3A::from_translation(Vec3::new(0.0, 0.0, 5.0));
        let far = Affine3A::from_translation(Vec3::new(0.0, 0.0, 5.5));
        // The far one first: the near one has the higher index but the smaller t.
        let w = World::build(
            vec![Instance::new(mesh.clone(), far).unwrap().into(), Instance::new(mesh, near).unwrap().into()],
            AccelKind::None,
        )
        .unwrap();
        let ray = Ray::new(Vec3::new(0.25, 0.75, 0.0), Vec3::Z);
        let hit: WorldHit = w.closest_hit(&ray, &mut NoCount).unwrap();
        assert_eq!((hit.object, hit.t), (1, 5.0));
        // The face z = 0 is triangles 0 and 1; (0.25, 0.75) lies in the second.
        assert_eq!(hit.prim, 0);
        assert_eq!(w.geometric_normal(&hit, ray.at(hit.t)), -Vec3::Z);
        assert!(!w.any_hit(&Ray::segment(Vec3::new(0.25, 0.75, 0.0), Vec3::Z, 0.0, 4.9), &mut NoCount));
    }
}
