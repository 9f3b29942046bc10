//! The two ray queries as the integrators ask them: the world's, except that a ray passes through
//! the texels of a surface that are cut out (glTF `alphaMode` `MASK`, MTL `d` and `map_d`) or, in
//! proportion to their transparency, partly covered (`BLEND`). This is the any-hit filter of the
//! traversal, as Embree's intersection filter functions do it: a rejected candidate is as if its
//! triangle were not there, for closest-hit and shadow rays alike. The coverage is read in the
//! texture coordinate set of the texture that holds it (the base colour texture's, in glTF).
//!
//! A partly covered surface is passed through with probability `1 - alpha` (stochastic
//! transparency, Enderton, Sintorn, Shirley and Luebke 2010), decided by a hash of the hit (object,
//! triangle, and the bits of its barycentric coordinates), so that a closest-hit query and a shadow
//! ray that meet the same point of the same surface decide alike, and a render stays the same bytes
//! on any number of threads.
//!
//! The same filter culls back faces: a triangle of a single-sided material (glTF `doubleSided:
//! false`, see [`englobe_scene::Material::culls_back_faces`]) is not there for a ray that meets it
//! from behind (the side against its winding's normal), as a rasteriser's back-face culling
//! hides it. Scenes with neither cut-outs nor single-sided triangles run the unfiltered queries,
//! at no cost.

use englobe::{Counters, Object, Ray, Shape, World, WorldHit};
use englobe_scene::Scene;

/// The world's queries with the scene's cut-outs applied.
pub struct Visibility<'a> {
    scene: &'a Scene,
    world: &'a World,
    /// Whether some material has a coverage to test or back faces to cull.
    filtered: bool,
}

/// A number in `[0, 1)` from the hit alone (SplitMix64's finaliser over its identifiers).
fn hit_number(h: &WorldHit) -> f32 {
    let mut x = (h.object as u64) << 32 ^ h.prim as u64;
    x ^= (h.u.to_bits() as u64) << 32 | h.v.to_bits() as u64;
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^= x >> 31;
    (x >> 40) as f32 / (1u64 << 24) as f32
}

impl<'a> Visibility<'a> {
    /// The queries of `world`, built over the objects of `scene` in order.
    pub fn new(scene: &'a Scene, world: &'a World) -> Self {
        let filtered = scene.materials.iter().any(|m| m.has_cutouts() || m.culls_back_faces());
        Visibility { scene, world, filtered }
    }

    /// The world.
    pub fn world(&self) -> &'a World {
        self.world
    }

    /// Whether `hit` of `ray` is on a surface that is there: not a culled back face, and not cut
    /// out (or covered at this point).
    fn solid(&self, ray: &Ray, hit: &WorldHit) -> bool {
        let object = &self.scene.objects[hit.object as usize];
        let m = &self.scene.materials[object.material_of(hit.prim) as usize];
        if m.culls_back_faces() && self.is_back_face(ray, hit) {
            return false;
        }
        if !m.has_cutouts() {
            return true;
        }
        // The coverage is read in the set of the texture that holds it (the base colour's in glTF).
        let set1 = m.textures.coverage_set() == 1;
        !m.passes_through(&self.scene.textures, object.tex_coords(set1, hit.prim, hit.u, hit.v), hit_number(hit))
    }

    /// True when `ray` meets the triangle of `hit` from behind. Other shapes have no back face
    /// to cull: their inside is not a side a viewer could be shown.
    fn is_back_face(&self, ray: &Ray, hit: &WorldHit) -> bool {
        let object = &self.world.objects()[hit.object as usize];
        if !matches!(object, Object::Shape(Shape::Triangle(_)) | Object::Mesh(_) | Object::Instance(_)) {
            return false;
        }
        let p = self.world.hit_point(ray, hit);
        ray.dir().dot(self.world.geometric_normal(hit, p)) > 0.0
    }

    /// The closest hit on a surface that is there.
    #[inline]
    pub fn closest_hit<C: Counters>(&self, ray: &Ray, counters: &mut C) -> Option<WorldHit> {
        if self.filtered {
            self.world.closest_hit_filtered(ray, counters, |h: &WorldHit| self.solid(ray, h))
        } else {
            self.world.closest_hit(ray, counters)
        }
    }

    /// [`Visibility::closest_hit`] of each ray, `hits[i]` for `rays[i]`, the rays traced in
    /// packets of sixteen (see [`World::closest_hit_packet`]) unless cut-outs need a filter. The
    /// two slices are as long.
    pub fn closest_hit_packet<C: Counters>(&self, rays: &[Ray], hits: &mut [Option<WorldHit>], counters: &mut C) {
        debug_assert_eq!(rays.len(), hits.len());
        if self.filtered {
            for (h, r) in hits.iter_mut().zip(rays) {
                *h = self.closest_hit(r, counters);
            }
        } else {
            self.world.closest_hit_packet(rays, hits, counters).expect("as many places as rays");
        }
    }

    /// [`Visibility::any_hit`] of each ray, `blocked[i]` for `rays[i]`, the rays traced in
    /// packets of sixteen (see [`World::any_hit_packet`]) unless cut-outs need a filter. The two
    /// slices are as long.
    pub fn any_hit_packet<C: Counters>(&self, rays: &[Ray], blocked: &mut [bool], counters: &mut C) {
        debug_assert_eq!(rays.len(), blocked.len());
        if self.filtered {
            for (b, r) in blocked.iter_mut().zip(rays) {
                *b = self.any_hit(r, counters);
            }
        } else {
            self.world.any_hit_packet(rays, blocked, counters).expect("as many places as rays");
        }
    }

    /// Whether a surface that is there lies within the ray's interval.
    #[inline]
    pub fn any_hit<C: Counters>(&self, ray: &Ray, counters: &mut C) -> bool {
        if self.filtered {
            self.world.any_hit_filtered(ray, counters, |h: &WorldHit| self.solid(ray, h))
        } else {
            self.world.any_hit(ray, counters)
        }
    }
}
