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
use crate::accel::{Accel, AccelKind, AnyAccel, Counters, Hit, StructureStats, TriangleBvh};
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

    /// The closest triangle hit by `ray`, given in the mesh's space: `prim` is the triangle.
    #[inline]
    pub fn closest_hit<C: Counters>(&self, ray: &Ray, counters: &mut C) -> Option<Hit> {
        match &self.accel {
            BottomAccel::Triangles(t) => t.closest_hit(ray, counters),
            BottomAccel::Generic(accel) => {
                // The mesh's box first: brute force has no root box of its own to skip the mesh with.
                counters.box_tests(1);
                accel.bounds().intersect(ray)?;
                let w = WatertightRay::new(ray);
                accel.closest_hit(ray, counters, |tri, r| self.mesh.intersect_with(tri, r, &w))
            }
        }
    }

    /// Whether `ray`, given in the mesh's space, hits a triangle within its interval.
    #[inline]
    pub fn any_hit<C: Counters>(&self, ray: &Ray, counters: &mut C) -> bool {
        match &self.accel {
            BottomAccel::Triangles(t) => t.any_hit(ray, counters),
            BottomAccel::Generic(accel) => {
                counters.box_tests(1);
                if accel.bounds().intersect(ray).is_none() {
                    return false;
                }
                let w = WatertightRay::new(ray);
                accel.any_hit(ray, counters, |tri, r| self.mesh.intersect_with(tri, r, &w).is_some())
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

#[cfg(test)]
mod tests {
    use glam::{Affine3A, Quat, Vec3};
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::*;
    use crate::accel::{NoCount, WorkCounts};
    use crate::shapes::{Instance, Sphere};
    use crate::{World, WorldHit};

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
    fn on_the_fast_path_every_mesh_is_a_triangle_bvh() {
        let mesh = cube();
        let objects: Vec<Object> = vec![
            Object::Mesh(mesh.clone()),
            Instance::new(mesh.clone(), Affine3A::from_translation(Vec3::X * 3.0)).unwrap().into(),
            Object::Mesh(cube()),
            Sphere::new(Vec3::new(0.0, 5.0, 0.0), 1.0).into(),
        ];
        let w = World::build(objects, AccelKind::BvhWide).unwrap();
        assert_eq!(w.bottom_levels().len(), 1);
        assert!(w.bottom_levels()[0].triangle_bvh().is_some());
        // The plain meshes' triangles in one structure, the instance and the sphere in the other.
        assert_eq!(w.triangles().unwrap().stats().prim_refs, 24);
        assert_eq!(w.accel().stats().prim_refs, 2);
        assert_eq!(w.primitive_count(), 12 + 1 + 12 + 1);
        assert_eq!(w.stats().prim_refs, 12 + 1 + 12 + 1);
        let hit = w.closest_hit(&Ray::new(Vec3::new(3.25, 0.75, -1.0), Vec3::Z), &mut NoCount).unwrap();
        assert_eq!((hit.object, hit.prim, hit.t), (1, 0, 1.0));
        let hit = w.closest_hit(&Ray::new(Vec3::new(0.25, 0.75, -1.0), Vec3::Z), &mut NoCount).unwrap();
        assert_eq!((hit.object, hit.prim, hit.t), (0, 0, 1.0), "the first of two identical meshes");
        let hit = w.closest_hit(&Ray::new(Vec3::new(0.0, 9.0, 0.0), -Vec3::Y), &mut NoCount).unwrap();
        assert_eq!((hit.object, hit.prim, hit.t), (3, 0, 3.0));
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
        for kind in [AccelKind::None, AccelKind::BvhWide, AccelKind::KdTree] {
            // The far one first: the near one has the higher index but the smaller t.
            let w = World::build(
                vec![
                    Instance::new(mesh.clone(), far).unwrap().into(),
                    Instance::new(mesh.clone(), near).unwrap().into(),
                ],
                kind,
            )
            .unwrap();
            let ray = Ray::new(Vec3::new(0.25, 0.75, 0.0), Vec3::Z);
            let hit: WorldHit = w.closest_hit(&ray, &mut NoCount).unwrap();
            assert_eq!((hit.object, hit.t), (1, 5.0), "{kind}");
            // The face z = 0 is triangles 0 and 1; (0.25, 0.75) lies in the second.
            assert_eq!(hit.prim, 0, "{kind}");
            assert_eq!(w.geometric_normal(&hit, ray.at(hit.t)), -Vec3::Z);
            assert!(!w.any_hit(&Ray::segment(Vec3::new(0.25, 0.75, 0.0), Vec3::Z, 0.0, 4.9), &mut NoCount));
        }
    }
}
