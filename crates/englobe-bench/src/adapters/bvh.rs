//! bvh 0.13 (svenstaro/bvh) under test: its binary SAH BVH built in parallel (`build_par`), walked
//! with the allocation-free `traverse_iterator`, which yields every triangle whose box the ray
//! crosses (the crate's ray has no interval to shrink, so a closest-hit query tests them all). The
//! crate's own triangle test culls back faces, so the adapter uses the two-sided Möller-Trumbore
//! test of [`super::moller_trumbore`] on the same vertices.

use bvh::aabb::{Aabb, Bounded};
use bvh::bounding_hierarchy::{BHShape, BoundingHierarchy};
use bvh::bvh::Bvh;
use bvh::ray::Ray;
use englobe::Vec3;
use nalgebra::{Point3, Vector3};

use super::moller_trumbore;
use crate::library::{BenchRay, Library, RayResult};
use crate::scene::BenchScene;

/// A triangle as the crate wants its shapes: bounded and told its node.
#[derive(Clone, Debug)]
struct Shape {
    vertices: [Vec3; 3],
    index: u32,
    node: usize,
}

impl Bounded<f32, 3> for Shape {
    fn aabb(&self) -> Aabb<f32, 3> {
        let [a, b, c] = self.vertices;
        let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
        Aabb::with_bounds(Point3::new(lo.x, lo.y, lo.z), Point3::new(hi.x, hi.y, hi.z))
    }
}

impl BHShape<f32, 3> for Shape {
    fn set_bh_node_index(&mut self, index: usize) {
        self.node = index;
    }

    fn bh_node_index(&self) -> usize {
        self.node
    }
}

/// bvh, built.
pub struct BvhLibrary {
    bvh: Bvh<f32, 3>,
    shapes: Vec<Shape>,
}

impl BvhLibrary {
    /// Builds the BVH over the scene's triangles (with rayon's current pool).
    pub fn build(scene: &BenchScene) -> Self {
        let mut shapes: Vec<Shape> = scene
            .triangle_soup()
            .enumerate()
            .map(|(i, vertices)| Shape { vertices, index: i as u32, node: 0 })
            .collect();
        let bvh = Bvh::build_par(&mut shapes);
        BvhLibrary { bvh, shapes }
    }

    #[inline(always)]
    fn ray(r: &BenchRay) -> Ray<f32, 3> {
        Ray::new(Point3::new(r.origin.x, r.origin.y, r.origin.z), Vector3::new(r.dir.x, r.dir.y, r.dir.z))
    }
}

impl Library for BvhLibrary {
    fn structure(&self) -> String {
        "Bvh build_par; traverse_iterator + two-sided Moller-Trumbore".to_owned()
    }

    fn closest_hits(&self, rays: &[BenchRay], out: &mut [RayResult]) {
        for (r, out) in rays.iter().zip(out) {
            let ray = Self::ray(r);
            let mut best = RayResult::MISS;
            for shape in self.bvh.traverse_iterator(&ray, &self.shapes) {
                if let Some(t) =
                    moller_trumbore::intersect(r.origin, r.dir, r.t_min, best.t.min(r.t_max), shape.vertices)
                    && (t < best.t || (t == best.t && shape.index < best.prim))
                {
                    best = RayResult::hit(t, shape.index);
                }
            }
            *out = best;
        }
    }

    fn any_hits(&self, rays: &[BenchRay], out: &mut [bool]) {
        for (r, out) in rays.iter().zip(out) {
            let ray = Self::ray(r);
            *out = self
                .bvh
                .traverse_iterator(&ray, &self.shapes)
                .any(|s| moller_trumbore::intersect(r.origin, r.dir, r.t_min, r.t_max, s.vertices).is_some());
        }
    }
}
