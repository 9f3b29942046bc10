//! The two queries of a [`World`], closest hit and any hit, over its structures in turn: on the
//! fast path the plain meshes' triangles first (their closest hit bounds what follows), then the
//! structure over the other bounded primitives, whose closure tests shapes exactly and sends
//! instances down to their bottom level, then the unbounded shapes (`planes.rs`).
//!
//! Each step keeps the closest hit under one rule: closer, or as close on a lower object, or on
//! the same object a lower primitive. Primitives are numbered object after object, so that is the
//! rule every structure applies to primitive numbers ([`crate::accel::HitRecord::offer`]), and the
//! answer is brute force's whichever structure holds which primitive.

use super::bottom::ClosestInstance;
use super::{Object, World, WorldHit};
use crate::PrimHit;
use crate::Ray;
use crate::accel::{Accel, Counters, Hit, HitFilter, NoCount, NoFilter};
use crate::shapes::{Instance, Intersect, WatertightRay};

/// Whether `hit` beats `best` under the rule of the module.
#[inline(always)]
pub(super) fn beats(hit: &WorldHit, best: Option<&WorldHit>) -> bool {
    best.is_none_or(|b| hit.t < b.t || (hit.t == b.t && (hit.object, hit.prim) < (b.object, b.prim)))
}

impl World {
    /// Whether [`World::accel`] holds anything (on the fast path, whether there are shapes or
    /// instances beside the meshes): a world of meshes and planes skips its query.
    #[inline(always)]
    pub(super) fn accel_in_use(&self) -> bool {
        self.accel_prims.as_ref().is_none_or(|p| !p.is_empty())
    }

    /// The world's primitive number of primitive `i` of [`World::accel`].
    #[inline(always)]
    pub(super) fn accel_prim(&self, i: u32) -> u32 {
        self.accel_prims.as_ref().map_or(i, |p| p[i as usize])
    }

    /// The closest hit of `ray` (in world space) with the mesh of `inst`, object `object`, among
    /// those `filter` accepts: `prim` of the answer is the triangle, `t` is the world ray's
    /// parameter.
    #[inline]
    fn instance_closest_hit<C: Counters, F: HitFilter<WorldHit>>(
        &self,
        object: u32,
        inst: &Instance,
        ray: &Ray,
        c: &mut C,
        filter: &mut F,
    ) -> Option<Hit> {
        let bottom = &self.bottom[self.object_bottom[object as usize] as usize];
        bottom.closest_hit_filtered(&inst.local_ray(ray), c, InObject { object, filter })
    }

    /// Whether `ray` hits the mesh of `inst` within its interval, where `filter` accepts.
    #[inline]
    fn instance_any_hit<C: Counters, F: HitFilter<WorldHit>>(
        &self,
        object: u32,
        inst: &Instance,
        ray: &Ray,
        c: &mut C,
        filter: &mut F,
    ) -> bool {
        let bottom = &self.bottom[self.object_bottom[object as usize] as usize];
        bottom.any_hit_filtered(&inst.local_ray(ray), c, InObject { object, filter })
    }

    /// The closest hit, or `None`. Ties at equal `t` go to the lower object (then primitive) index.
    #[inline]
    pub fn closest_hit<C: Counters>(&self, ray: &Ray, counters: &mut C) -> Option<WorldHit> {
        self.closest_hit_filtered(ray, counters, NoFilter)
    }

    /// Whether anything is hit within the ray's interval (shadow rays).
    #[inline]
    pub fn any_hit<C: Counters>(&self, ray: &Ray, counters: &mut C) -> bool {
        self.any_hit_filtered(ray, counters, NoFilter)
    }

    /// [`World::closest_hit`] among the hits `filter` accepts (see
    /// [`crate::accel::interface::filter`]): a hit the filter rejects is as if its primitive
    /// were not there, for this query.
    ///
    /// ```
    /// use englobe::{AccelKind, NoCount, Ray, Sphere, Vec3, World, WorldHit};
    ///
    /// let spheres = vec![Sphere::new(Vec3::Z * 3.0, 1.0).into(), Sphere::new(Vec3::Z * 8.0, 1.0).into()];
    /// let world = World::build(spheres, AccelKind::BvhWide)?;
    /// let ray = Ray::new(Vec3::ZERO, Vec3::Z);
    /// let hit = world.closest_hit_filtered(&ray, &mut NoCount, |h: &WorldHit| h.object != 0).expect("the far sphere");
    /// assert_eq!((hit.object, hit.t), (1, 7.0));
    /// # Ok::<(), englobe::WorldError>(())
    /// ```
    pub fn closest_hit_filtered<C: Counters, F: HitFilter<WorldHit>>(
        &self,
        ray: &Ray,
        counters: &mut C,
        mut filter: F,
    ) -> Option<WorldHit> {
        if !ray.is_valid() {
            return None;
        }
        let best = self
            .triangles
            .as_ref()
            .and_then(|t| t.closest_hit_of_valid(ray, counters, Located { world: self, filter: &mut filter }))
            .map(|h| self.mesh_hit(h));
        self.closest_beyond_meshes(ray, best, counters, &mut filter)
    }

    /// A hit on the meshes' triangle tree, as the world names it.
    #[inline(always)]
    pub(super) fn mesh_hit(&self, h: Hit) -> WorldHit {
        let (object, prim) = self.locate(h.prim);
        WorldHit { t: h.t, object, prim, u: h.u, v: h.v }
    }

    /// The closest hit of a valid `ray`, given `best`, the closest on the meshes' triangle tree:
    /// the shapes and instances, then the unbounded shapes.
    #[inline(always)]
    pub(super) fn closest_beyond_meshes<C: Counters, F: HitFilter<WorldHit>>(
        &self,
        ray: &Ray,
        mut best: Option<WorldHit>,
        counters: &mut C,
        filter: &mut F,
    ) -> Option<WorldHit> {
        best = self.closest_in_accel(ray, best, counters, filter);
        self.closest_unbounded(ray, best, counters, filter)
    }

    /// The closest hit of a valid `ray`, given `best`, the closest on the meshes' triangle tree:
    /// the shapes and instances (the unbounded shapes left out).
    #[inline(always)]
    pub(super) fn closest_in_accel<C: Counters, F: HitFilter<WorldHit>>(
        &self,
        ray: &Ray,
        best: Option<WorldHit>,
        counters: &mut C,
        filter: &mut F,
    ) -> Option<WorldHit> {
        if self.accel_in_use()
            && let Some(hit) = self.accel_closest_hit(ray, best.map_or(ray.t_max, |b| b.t), counters, filter)
            && beats(&hit, best.as_ref())
        {
            return Some(hit);
        }
        best
    }

    /// The closest hit among the primitives of [`World::accel`] (shapes, instances, and on the
    /// teaching structures the meshes' triangles) before `t_max`.
    fn accel_closest_hit<C: Counters, F: HitFilter<WorldHit>>(
        &self,
        ray: &Ray,
        t_max: f32,
        counters: &mut C,
        filter: &mut F,
    ) -> Option<WorldHit> {
        // Work inside instances is counted apart (the structure holds `counters` during its query)
        // and merged afterwards.
        let mut nested = C::default();
        let mut instance_hits = ClosestInstance::default();
        // Only the teaching structures test mesh triangles through their closure.
        let mut watertight = None;
        let bounded = ray.with_range(ray.t_min, t_max);
        let found = self.accel.closest_hit(&bounded, counters, |i, r| {
            self.accel_item_closest(i, r, &mut watertight, &mut nested, &mut instance_hits, filter)
        });
        counters.merge(&nested);
        Some(self.accel_world_hit(ray, found?, &instance_hits, filter))
    }

    /// The hit of `r` on primitive `i` of [`World::accel`] (what the structure's closure
    /// answers): `r` is the query's ray shrunk to its closest hit so far. Work inside instances
    /// is counted in `nested`, their hits kept in `instance_hits`; a plain mesh's triangle (the
    /// teaching structures only) is tested with `watertight`, made at the first.
    #[inline(always)]
    pub(super) fn accel_item_closest<C: Counters, F: HitFilter<WorldHit>>(
        &self,
        i: u32,
        r: &Ray,
        watertight: &mut Option<WatertightRay>,
        nested: &mut C,
        instance_hits: &mut ClosestInstance,
        filter: &mut F,
    ) -> Option<PrimHit> {
        let (object, local) = self.locate(self.accel_prim(i));
        let h = match &self.objects[object as usize] {
            Object::Shape(s) => s.intersect(r)?,
            Object::Mesh(m) => m.intersect_with(local, r, watertight.get_or_insert_with(|| WatertightRay::new(r)))?,
            Object::Instance(inst) => {
                let hit = self.instance_closest_hit(object, inst, r, nested, filter)?;
                instance_hits.offer(i, &hit);
                return Some(PrimHit { t: hit.t, u: hit.u, v: hit.v });
            }
        };
        let candidate = WorldHit { t: h.t, object, prim: local, u: h.u, v: h.v };
        (F::ACCEPTS_ALL || filter.accept(&candidate)).then_some(h)
    }

    /// The world's name for `h`, the closest hit of `ray` on [`World::accel`]: an instance's hit
    /// names its triangle, kept in `instance_hits`.
    #[inline]
    pub(super) fn accel_world_hit<F: HitFilter<WorldHit>>(
        &self,
        ray: &Ray,
        h: Hit,
        instance_hits: &ClosestInstance,
        filter: &mut F,
    ) -> WorldHit {
        let (object, local) = self.locate(self.accel_prim(h.prim));
        let prim = match &self.objects[object as usize] {
            Object::Instance(inst) => instance_hits.triangle(h.prim, h.t).unwrap_or_else(|| {
                // Only a structure that breaks the tie rule of `HitRecord::offer` gets here:
                // ask the instance again, up to the hit.
                let r = ray.with_range(ray.t_min, h.t);
                self.instance_closest_hit(object, inst, &r, &mut NoCount, filter).map_or(0, |x| x.prim)
            }),
            _ => local,
        };
        WorldHit { t: h.t, object, prim, u: h.u, v: h.v }
    }

    /// [`World::any_hit`] counting only the hits `filter` accepts.
    pub fn any_hit_filtered<C: Counters, F: HitFilter<WorldHit>>(
        &self,
        ray: &Ray,
        counters: &mut C,
        mut filter: F,
    ) -> bool {
        if !ray.is_valid() {
            return false;
        }
        self.any_unbounded(ray, counters, &mut filter)
            || self
                .triangles
                .as_ref()
                .is_some_and(|t| t.any_hit_of_valid(ray, counters, Located { world: self, filter: &mut filter }))
            || self.any_in_accel(ray, counters, &mut filter)
    }

    /// Whether a valid `ray` hits one of the primitives of [`World::accel`] (shapes, instances).
    #[inline]
    pub(super) fn any_in_accel<C: Counters, F: HitFilter<WorldHit>>(
        &self,
        ray: &Ray,
        counters: &mut C,
        filter: &mut F,
    ) -> bool {
        if !self.accel_in_use() {
            return false;
        }
        let mut nested = C::default();
        let mut watertight = None;
        let hit =
            self.accel.any_hit(ray, counters, |i, r| self.accel_item_any(i, r, &mut watertight, &mut nested, filter));
        counters.merge(&nested);
        hit
    }

    /// Whether `r` hits primitive `i` of [`World::accel`] where `filter` accepts (see
    /// [`World::accel_item_closest`]).
    #[inline(always)]
    pub(super) fn accel_item_any<C: Counters, F: HitFilter<WorldHit>>(
        &self,
        i: u32,
        r: &Ray,
        watertight: &mut Option<WatertightRay>,
        nested: &mut C,
        filter: &mut F,
    ) -> bool {
        let (object, local) = self.locate(self.accel_prim(i));
        let h = match &self.objects[object as usize] {
            Object::Shape(s) => s.intersect(r),
            Object::Mesh(m) => m.intersect_with(local, r, watertight.get_or_insert_with(|| WatertightRay::new(r))),
            Object::Instance(inst) => return self.instance_any_hit(object, inst, r, nested, filter),
        };
        h.is_some_and(|h| F::ACCEPTS_ALL || filter.accept(&WorldHit { t: h.t, object, prim: local, u: h.u, v: h.v }))
    }
}

/// A world filter seen by the plain meshes' [`crate::TriangleBvh`]: its triangle numbers are the
/// world's primitive numbers, turned into an object and its triangle.
struct Located<'a, F> {
    world: &'a World,
    filter: &'a mut F,
}

impl<F: HitFilter<WorldHit>> HitFilter<Hit> for Located<'_, F> {
    const ACCEPTS_ALL: bool = F::ACCEPTS_ALL;

    #[inline(always)]
    fn accept(&mut self, h: &Hit) -> bool {
        self.filter.accept(&self.world.mesh_hit(*h))
    }
}

/// A world filter seen by an instance's bottom level: its triangles are the object's.
struct InObject<'a, F> {
    object: u32,
    filter: &'a mut F,
}

impl<F: HitFilter<WorldHit>> HitFilter<Hit> for InObject<'_, F> {
    const ACCEPTS_ALL: bool = F::ACCEPTS_ALL;

    #[inline(always)]
    fn accept(&mut self, h: &Hit) -> bool {
        self.filter.accept(&WorldHit { t: h.t, object: self.object, prim: h.prim, u: h.u, v: h.v })
    }
}

#[cfg(test)]
mod tests {
    use glam::{Affine3A, Quat, Vec3};
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use std::sync::Arc;

    use super::*;
    use crate::AccelKind;
    use crate::accel::{NoCount, WorkCounts};
    use crate::shapes::{Instance, Sphere, TriangleMesh};

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
