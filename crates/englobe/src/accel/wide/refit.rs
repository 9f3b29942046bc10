//! Refitting a [`TriangleBvh`] after its triangles moved, the topology unchanged (a skinned or
//! simulated mesh, frame after frame): every triangle stays in its block lane and every node keeps
//! its children; the blocks take the new vertices and the boxes are recomputed bottom-up. This is
//! the refit of Wald, Boulos and Shirley (2007), "Ray Tracing Deformable Scenes Using Dynamic
//! Bounding Volume Hierarchies" (ACM TOG 26(1)), and Embree's `RTC_BUILD_QUALITY_REFIT`.
//!
//! A refitted tree answers exactly as a fresh build does (every box is still the exact union of
//! what it holds), but its boxes may overlap more as the mesh deforms, so queries slow down. The
//! SAH cost says how much: [`RefitReport`] gives the refitted tree's and the cost the tree had
//! when it was built, and a caller rebuilds when their ratio grows too large (Wald et al. rebuild
//! at a fixed ratio; Embree leaves it to the caller too).
//!
//! The wide nodes are stored parents before children (the conversion appends a node's children
//! after it, and the subtrees it converts in parallel after the root), so one pass over the nodes
//! in reverse order sees every child before its parent.
//!
//! The structure leaves out triangles that can never be hit (zero area, non-finite corners). If
//! a stored triangle becomes one of them, or a left-out one stops being one, the leaves no longer
//! hold the right set and the structure is rebuilt instead: the report says so.

use glam::Vec3;

use super::TriangleBvh;
use super::node::{EMPTY, WIDTH, index_of, is_leaf};
use super::triangle_bvh::triangle_of;
use super::triangles::{LANES, TriBlock, UNUSED, is_storable};
use crate::Aabb;
use crate::accel::MAX_PRIMITIVES;
use crate::accel::bvh::build::parallel::{all_mut, map_chunks};
use crate::accel::bvh::stats::{SAH_INTERSECTION_COST, SAH_TRAVERSAL_COST};
use crate::shapes::{MeshError, TriangleMesh, check_arrays};

/// What a refit did, and the quality of the tree it left.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefitReport {
    /// True if the structure had to be rebuilt (the set of triangles that can be hit changed).
    pub rebuilt: bool,
    /// The SAH cost of the tree now ([`TriangleBvh::sah_cost`]).
    pub sah_cost: f32,
    /// Its SAH cost when it was last built.
    pub built_sah_cost: f32,
}

impl RefitReport {
    /// `sah_cost / built_sah_cost`: 1 right after a build, growing as refits loosen the tree (1
    /// for an empty tree). A caller typically rebuilds past 1.5 to 2.
    pub fn cost_ratio(&self) -> f32 {
        if self.built_sah_cost > 0.0 { self.sah_cost / self.built_sah_cost } else { 1.0 }
    }
}

/// Why a refit was refused (the structure is then left as it was).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RefitError {
    /// The triangles are not as many as the structure was built over.
    #[error("the structure was built over {built} triangles, the refit gives {given}")]
    TriangleCount {
        /// Triangles at the build.
        built: usize,
        /// Triangles given now.
        given: usize,
    },
    /// The plain arrays given are not a mesh.
    #[error(transparent)]
    Mesh(#[from] MeshError),
}

impl TriangleBvh {
    /// The surface area heuristic cost of the tree: a wide node reached costs
    /// [`SAH_TRAVERSAL_COST`], a leaf [`SAH_INTERSECTION_COST`] per triangle, each weighted by the
    /// chance `area(box) / area(root)` that a ray through the root's box enters it (1 when the
    /// root box is flat). 0 for an empty tree.
    pub fn sah_cost(&self) -> f32 {
        if self.nodes.is_empty() {
            return 0.0;
        }
        let root = self.bounds.surface_area() as f64;
        let chance = |b: &Aabb| if root > 0.0 { b.surface_area() as f64 / root } else { 1.0 };
        // The nodes in fixed pieces, in parallel, their sums added in order: the same cost
        // whatever the threads.
        let pieces = map_chunks(&self.nodes, 1 << 12, |nodes| {
            let mut cost = 0.0;
            for node in nodes {
                for slot in (0..WIDTH).filter(|&s| node.children[s] != EMPTY) {
                    let (c, b) = (node.children[slot], node.child_bounds(slot));
                    cost += chance(&b)
                        * if is_leaf(c) {
                            let first = index_of(c) as usize;
                            let tris: u32 =
                                self.blocks[first..first + node.counts[slot] as usize].iter().map(TriBlock::used).sum();
                            SAH_INTERSECTION_COST as f64 * tris as f64
                        } else {
                            SAH_TRAVERSAL_COST as f64
                        };
                }
            }
            cost
        });
        pieces.into_iter().fold(SAH_TRAVERSAL_COST as f64, |sum, piece| sum + piece) as f32
    }

    /// The SAH cost the tree had when it was built.
    pub fn built_sah_cost(&self) -> f32 {
        self.built_sah_cost.unwrap_or_else(|| self.sah_cost())
    }

    /// Refits the structure to the moved vertices of `mesh`, built from the same mesh (the same
    /// triangles, the vertices moved). See the [module](self).
    pub fn refit(&mut self, mesh: &TriangleMesh) -> Result<RefitReport, RefitError> {
        self.refit_with(mesh.len(), |i| mesh.triangle(i).vertices)
    }

    /// Refits the structure to plain arrays (see [`TriangleBvh::from_arrays`]), checked first.
    ///
    /// ```
    /// use englobe::{NoCount, Ray, TriangleBvh, Vec3};
    ///
    /// let mut vertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    /// let mut bvh = TriangleBvh::from_arrays(&vertices, &[[0, 1, 2]])?;
    /// for v in &mut vertices {
    ///     v[2] += 2.0; // the triangle moves up
    /// }
    /// let report = bvh.refit_arrays(&vertices, &[[0, 1, 2]])?;
    /// assert!(!report.rebuilt && report.cost_ratio() == 1.0);
    /// let hit = bvh.closest_hit(&Ray::new(Vec3::new(0.2, 0.2, 5.0), -Vec3::Z), &mut NoCount).expect("a hit");
    /// assert_eq!(hit.t, 3.0);
    /// # Ok::<(), englobe::accel::wide::RefitError>(())
    /// ```
    pub fn refit_arrays(&mut self, vertices: &[[f32; 3]], triangles: &[[u32; 3]]) -> Result<RefitReport, RefitError> {
        check_arrays(vertices, triangles)?;
        self.refit_with(triangles.len(), triangle_of(vertices, triangles))
    }

    /// Refits the structure to `count` triangles, triangle `i` given by `triangle(i)`: the same
    /// count and numbering as at the build.
    pub fn refit_with(
        &mut self,
        count: usize,
        triangle: impl Fn(u32) -> [Vec3; 3] + Sync,
    ) -> Result<RefitReport, RefitError> {
        let given = count.min(MAX_PRIMITIVES);
        if given != self.count {
            return Err(RefitError::TriangleCount { built: self.count, given: count });
        }
        let hittable = |v: &[Vec3; 3]| v.iter().all(|p| p.is_finite()) && is_storable(v);
        // The blocks, their lanes kept; unused lanes repeat the first, as built.
        let mut scratch_ok = all_mut(&mut self.blocks, 1 << 10, |block| {
            let mut lanes = [(UNUSED, [Vec3::ZERO; 3]); LANES];
            let used = block.used() as usize;
            let mut ok = true;
            for (lane, slot) in lanes.iter_mut().enumerate().take(used) {
                let v = triangle(block.ids[lane]);
                ok &= hittable(&v);
                *slot = (block.ids[lane], v);
            }
            *block = TriBlock::new(&lanes[..used]);
            ok
        });
        // The left-out triangles must stay out.
        if scratch_ok && self.stored != self.count {
            let now = (0..count as u32).filter(|&i| hittable(&triangle(i))).count();
            scratch_ok = now == self.stored;
        }
        if !scratch_ok {
            let isa = self.isa;
            *self = TriangleBvh::build_with(count, triangle, self.options);
            self.isa = isa;
            let cost = self.built_sah_cost();
            return Ok(RefitReport { rebuilt: true, sah_cost: cost, built_sah_cost: cost });
        }
        // The cost as built: made now if this is the tree's first refit (its boxes are about to
        // move; the blocks' triangles, moved above, do not enter it).
        let built_sah_cost = self.built_sah_cost();
        // The boxes, children before parents.
        let mut node_box = vec![Aabb::EMPTY; self.nodes.len()];
        for i in (0..self.nodes.len()).rev() {
            let mut node = self.nodes[i];
            let mut all = Aabb::EMPTY;
            for slot in 0..WIDTH {
                let c = node.children[slot];
                if c == EMPTY {
                    continue;
                }
                let b = if is_leaf(c) {
                    let first = index_of(c) as usize;
                    self.blocks[first..first + node.counts[slot] as usize]
                        .iter()
                        .flat_map(|block| {
                            (0..block.used() as usize).map(|lane| Aabb::from_points(block.vertices(lane)))
                        })
                        .fold(Aabb::EMPTY, |a, b| a.union(&b))
                } else {
                    node_box[c as usize]
                };
                node.set_child(slot, &b, c, node.counts[slot]);
                all = all.union(&b);
            }
            self.nodes[i] = node;
            node_box[i] = all;
        }
        self.bounds = node_box.first().copied().unwrap_or(Aabb::EMPTY);
        self.built_sah_cost = Some(built_sah_cost);
        Ok(RefitReport { rebuilt: false, sah_cost: self.sah_cost(), built_sah_cost })
    }
}
