//! obvhs 0.4 under test: its compressed wide BVH (CwBvh, Ylitie, Karras and Laine 2017,
//! "Efficient Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs") built with the
//! `medium_build` preset (PLOC plus reinsertion, "around the same build time as Embree" by its
//! own account), traversed with `ray_traverse` (closest) and `ray_traverse_miss` (any hit), and
//! obvhs's own two-sided triangle test, on triangles reordered into the BVH's leaf order as its
//! examples do to save an indirection.

use std::time::Duration;

use obvhs::BvhBuildParams;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;

use crate::library::{BenchRay, Library, RayResult};
use crate::scene::BenchScene;

/// obvhs, built.
pub struct ObvhsLibrary {
    bvh: CwBvh,
    /// Triangles in the BVH's primitive order.
    triangles: Vec<Triangle>,
}

impl ObvhsLibrary {
    /// Builds the CwBvh over the scene's triangles (with rayon's current pool).
    pub fn build(scene: &BenchScene) -> Self {
        let soup: Vec<Triangle> =
            scene.triangle_soup().map(|[a, b, c]| Triangle { v0: a.into(), v1: b.into(), v2: c.into() }).collect();
        let bvh = build_cwbvh_from_tris(&soup, BvhBuildParams::medium_build(), &mut Duration::default());
        let triangles = bvh.primitive_indices.iter().map(|&i| soup[i as usize]).collect();
        ObvhsLibrary { bvh, triangles }
    }

    #[inline(always)]
    fn ray(r: &BenchRay) -> Ray {
        Ray::new(r.origin.into(), r.dir.into(), r.t_min, r.t_max)
    }
}

impl Library for ObvhsLibrary {
    fn structure(&self) -> String {
        "CwBvh medium_build; ray_traverse / ray_traverse_miss".to_owned()
    }

    fn closest_hits(&self, rays: &[BenchRay], out: &mut [RayResult]) {
        for (r, out) in rays.iter().zip(out) {
            let mut hit = RayHit::none();
            let found = self.bvh.ray_traverse(Self::ray(r), &mut hit, |ray, id| self.triangles[id].intersect(ray));
            *out = if found {
                RayResult::hit(hit.t, self.bvh.primitive_indices[hit.primitive_id as usize])
            } else {
                RayResult::MISS
            };
        }
    }

    fn any_hits(&self, rays: &[BenchRay], out: &mut [bool]) {
        for (r, out) in rays.iter().zip(out) {
            *out = !self.bvh.ray_traverse_miss(Self::ray(r), |ray, id| self.triangles[id].intersect(ray));
        }
    }
}
