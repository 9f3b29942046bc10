//! [`TriangleBvh`]: the fast path for triangle meshes. A wide BVH whose leaves hold the triangles
//! themselves, in blocks of four tested at once (see [`super::triangles`]), so that a query reads
//! no index and calls no closure: closest hit and any hit of a ray, answered as `(t, triangle,
//! u, v)`, exactly as the scalar watertight test and brute force would answer them.
//!
//! Built by the binned SAH builder's splits ([`BinnedSah`], parallel) straight into eight-wide
//! nodes ([`super::build`](mod@super::build)), with subtrees of up to four triangles collapsed
//! into one block.

use glam::Vec3;

use super::build::{build_wide, build_wide_refs};
use super::convert::{ConvertOptions, LeafSink};
use super::dispatch;
use super::isa::{Isa, IsaUnavailable};
use super::node::{NodeRay, WideNode, may_enter, reach};
use super::presplit::{TriangleBox, presplit_cuts};
use super::spatial::spatial_cuts;
use super::triangle_leaves;
use super::triangles::{LANES, TriBlock, UNUSED, is_storable};
use crate::accel::bvh::BinnedSah;
use crate::accel::bvh::build::parallel::{collect_indexed_huge, map_chunks};
use crate::accel::bvh::build::top_down::PrimRef;
use crate::accel::{Counters, Hit, HitFilter, LEAF_SIZE_BUCKETS, MAX_PRIMITIVES, NoFilter, StructureStats};
use crate::shapes::{MeshError, TriangleMesh, check_arrays};
use crate::{Aabb, Ray};

/// Extra references of the default build, in percent of the triangles: on the Sponza atrium
/// it cuts the primary rays' triangle tests by half and their node visits by a quarter.
pub const DEFAULT_PRESPLIT_PERCENT: u32 = 40;

/// Binary levels of spatial splits in the default build (on scenes with large triangles): on the
/// Sponza atrium 4 levels gave 5.92 wide nodes per random closest-hit ray, 6 levels 5.49 and 8
/// levels 5.44, for 3.6, 5.7 and 9.0 % more references.
pub const DEFAULT_SPATIAL_LEVELS: u32 = 6;

/// The SAH cost of a node in the default build, relative to one block test: twice the binary
/// trees' ([`crate::accel::bvh::SAH_TRAVERSAL_COST`]). A single ray's walk waits on each node
/// test before it can read the next node, while the blocks of one leaf are tested side by side;
/// so the tree stops splitting sooner, into larger leaves (on the Sponza atrium 23 % fewer wide
/// nodes, 3-4 % fewer visited per random ray and a fifth to a quarter more triangles tested):
/// single rays ran level to 8 % faster on the ogre and inside the Sponza, level on the bunny
/// (within 1.2 %), and packets level (`docs/performance.md`, "Since then: a node priced at one
/// block test").
pub const TRAVERSAL_COST: f32 = 1.0;

/// How a [`TriangleBvh`] is built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleBvhOptions {
    /// The binary tree's builder.
    pub builder: BinnedSah,
    /// Binary subtrees over at most this many triangles become one leaf.
    pub collapse: usize,
    /// Extra references the build may make by cutting the triangles whose boxes waste the most
    /// area, as a percentage of the triangle count (0: no triangle is cut; see
    /// [`super::presplit`]).
    ///
    /// The cut helps closest hits (fewer triangles tested near long, thin triangles) and costs
    /// occlusion queries on long rays, whose occluders are often those very triangles, now in
    /// pieces deeper in the tree: on the Sponza atrium, any-hit rays ran 8-21 % faster with 0,
    /// closest-hit rays up to 4 % slower, and the build took a quarter less time
    /// (`docs/performance.md`). A program that mostly asks whether anything is in the way can
    /// build with 0.
    pub presplit_percent: u32,
    /// Binary levels at the top of the tree whose splits may cut triangles, by the SAH (spatial
    /// splits, [`super::spatial`]), on a scene with large triangles; 0 for none. Where they run,
    /// they replace the pre-split; on a scene of even triangles (a scanned mesh, a tiling of
    /// one: see [`super::spatial::MIN_LARGE_WASTE`]) they do not run and the pre-split does.
    ///
    /// On the Sponza atrium, with the default [`DEFAULT_SPATIAL_LEVELS`], random rays visit a
    /// fifth fewer wide nodes for closest hits and over a quarter fewer for any hits than with
    /// the pre-split, and run 11-23 % faster, for a build that executes 37 % more instructions
    /// (`docs/performance.md`, "Since then: spatial splits in the top levels" and "Since then:
    /// the spatial pass's own passes").
    pub spatial_levels: u32,
}

impl Default for TriangleBvhOptions {
    fn default() -> Self {
        TriangleBvhOptions {
            // Triangles are tested four at a time, in blocks: the SAH counts blocks, and the
            // parallel partition's order shows only in leaves of several blocks (which one an
            // any-hit query tests first).
            builder: BinnedSah {
                small_leaf: LANES,
                block: LANES,
                parallel_partition: true,
                traversal_cost: TRAVERSAL_COST,
                ..BinnedSah::default()
            },
            collapse: LANES,
            presplit_percent: DEFAULT_PRESPLIT_PERCENT,
            spatial_levels: DEFAULT_SPATIAL_LEVELS,
        }
    }
}

/// A wide BVH over triangles, stored inline in blocks of four: the structure for fast ray
/// queries on meshes.
///
/// ```
/// use englobe::{NoCount, Ray, TriangleBvh, TriangleMesh, Vec3};
///
/// let mesh = TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]])?;
/// let bvh = TriangleBvh::build(&mesh);
/// let hit = bvh.closest_hit(&Ray::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z), &mut NoCount).expect("a hit");
/// assert_eq!((hit.prim, hit.t), (0, 1.0));
/// # Ok::<(), englobe::shapes::MeshError>(())
/// ```
#[derive(Clone, Debug)]
pub struct TriangleBvh {
    pub(super) nodes: Vec<WideNode>,
    pub(super) blocks: Vec<TriBlock>,
    pub(super) depth: u32,
    pub(super) bounds: Aabb,
    /// Triangles stored, each counted once however many leaves hold it (zero-area ones are left
    /// out: they are never hit).
    pub(super) stored: usize,
    /// Triangles given to the build (stored or left out).
    pub(super) count: usize,
    /// Whether some triangle lies in several leaves (it was cut before the build).
    pub(super) cut: bool,
    pub(super) options: TriangleBvhOptions,
    /// The SAH cost when built (see [`TriangleBvh::sah_cost`]), once the tree has been refitted;
    /// `None` before: the tree is then as built, and the cost is computed when asked for (it
    /// walks every node, a few percent of a build that most programs never ask for).
    pub(super) built_sah_cost: Option<f32>,
    pub(super) isa: Isa,
}

/// Triangle `i` of plain arrays whose indices were checked.
pub(super) fn triangle_of<'a>(
    vertices: &'a [[f32; 3]],
    triangles: &'a [[u32; 3]],
) -> impl Fn(u32) -> [Vec3; 3] + Sync + 'a {
    move |i| triangles[i as usize].map(|v| Vec3::from_array(vertices[v as usize]))
}

/// Packs leaves into blocks of four triangles: names each block's triangles as the conversion
/// meets its leaves; the blocks themselves are filled afterwards, in parallel ([`Blocks::fill`]).
struct Blocks<'a> {
    /// The triangle of each of the build's boxes (several boxes name one cut triangle); `None`
    /// when box `i` is triangle `i`.
    ids: Option<&'a [u32]>,
    /// Each block's triangles, [`UNUSED`] in the lanes beyond them.
    blocks: Vec<[u32; LANES]>,
    /// The leaf's triangles, each once.
    leaf_ids: Vec<u32>,
}

impl LeafSink for Blocks<'_> {
    fn max_prims(&self) -> usize {
        4 * LANES
    }

    fn leaf(&mut self, prims: &[u32]) -> (u32, u8) {
        let first = self.blocks.len() as u32;
        self.leaf_ids.clear();
        self.leaf_ids.extend(prims.iter().map(|&p| self.ids.map_or(p, |ids| ids[p as usize])));
        // Pieces of one cut triangle may meet in a leaf: it is stored there once.
        self.leaf_ids.sort_unstable();
        self.leaf_ids.dedup();
        for chunk in self.leaf_ids.chunks(LANES) {
            let mut block = [UNUSED; LANES];
            block[..chunk.len()].copy_from_slice(chunk);
            self.blocks.push(block);
        }
        (first, (self.blocks.len() as u32 - first) as u8)
    }

    type Item = [u32; LANES];

    fn split(&self) -> Self {
        Blocks { ids: self.ids, blocks: Vec::new(), leaf_ids: Vec::new() }
    }

    fn into_items(self) -> Vec<[u32; LANES]> {
        self.blocks
    }

    fn append(&mut self, items: &[[u32; LANES]]) -> u32 {
        let first = self.blocks.len() as u32;
        self.blocks.extend_from_slice(items);
        first
    }
}

impl Blocks<'_> {
    /// The blocks, their vertices fetched from `triangle` on every core: the fetches follow the
    /// leaves' order, not the mesh's, so they mostly miss the caches, and they were the largest
    /// sequential part of a build.
    fn fill(&self, triangle: impl Fn(u32) -> [Vec3; 3] + Sync) -> Vec<TriBlock> {
        collect_indexed_huge(self.blocks.len(), 1 << 12, |i| {
            let ids = &self.blocks[i];
            let used = ids.iter().take_while(|&&id| id != UNUSED).count();
            let mut triangles = [(UNUSED, [Vec3::ZERO; 3]); LANES];
            for (slot, &id) in triangles.iter_mut().zip(&ids[..used]) {
                *slot = (id, triangle(id));
            }
            TriBlock::new(&triangles[..used])
        })
    }
}

impl TriangleBvh {
    /// Builds the structure over the triangles of `mesh` (triangle indices are the mesh's).
    pub fn build(mesh: &TriangleMesh) -> Self {
        Self::build_with(mesh.len(), |i| mesh.triangle(i).vertices, TriangleBvhOptions::default())
    }

    /// Builds the structure over a triangle soup (triangle `i` is `triangles[i]`).
    pub fn from_triangles(triangles: &[[Vec3; 3]]) -> Self {
        Self::build_with(triangles.len(), |i| triangles[i as usize], TriangleBvhOptions::default())
    }

    /// Builds the structure over plain arrays: vertex positions as `[x, y, z]` and triangles as
    /// three vertex indices (triangle `i` is `triangles[i]`), read in place, never copied into a
    /// mesh. An index past the vertices or a non-finite coordinate is an error, never a panic.
    ///
    /// ```
    /// use englobe::{NoCount, Ray, TriangleBvh, Vec3};
    ///
    /// let vertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    /// let bvh = TriangleBvh::from_arrays(&vertices, &[[0, 1, 2]])?;
    /// assert!(bvh.any_hit(&Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z), &mut NoCount));
    /// assert!(TriangleBvh::from_arrays(&vertices, &[[0, 1, 3]]).is_err());
    /// # Ok::<(), englobe::shapes::MeshError>(())
    /// ```
    pub fn from_arrays(vertices: &[[f32; 3]], triangles: &[[u32; 3]]) -> Result<Self, MeshError> {
        check_arrays(vertices, triangles)?;
        Ok(Self::build_with(triangles.len(), triangle_of(vertices, triangles), TriangleBvhOptions::default()))
    }

    /// [`TriangleBvh::from_arrays`] from flat arrays: `x, y, z` of each vertex in turn and three
    /// indices per triangle, read in place (see [`TriangleMesh::from_flat`]).
    pub fn from_flat(vertices: &[f32], indices: &[u32]) -> Result<Self, MeshError> {
        Self::from_arrays(crate::shapes::triples(vertices, "vertices")?, crate::shapes::triples(indices, "indices")?)
    }

    /// Builds the structure over `count` triangles, triangle `i` given by `triangle(i)`, at most
    /// [`MAX_PRIMITIVES`] of them. Zero-area triangles are left out (they are never hit), and so
    /// are triangles with non-finite coordinates.
    pub fn build_with(count: usize, triangle: impl Fn(u32) -> [Vec3; 3] + Sync, options: TriangleBvhOptions) -> Self {
        let count = count.min(MAX_PRIMITIVES);
        // Each triangle's reference for the build, with the area its box wastes beside it for the
        // presplit, in the one pass that fetches the triangles; an empty box marks one left out.
        let mut refs = collect_indexed_huge(count, 1 << 14, |i| {
            let v = triangle(i as u32);
            if v.iter().all(|p| p.is_finite()) && is_storable(&v) {
                let t = TriangleBox::of(&v);
                PrimRef::with_spare(&t.bounds, i as u32, t.waste)
            } else {
                PrimRef::with_spare(&Aabb::EMPTY, i as u32, 0.0)
            }
        });
        // The triangles kept, in order (each reference still names its triangle).
        let all_kept = map_chunks(&refs, 1 << 14, |c| c.iter().all(|r| r.bounds().is_finite())).into_iter().all(|a| a);
        if !all_kept {
            refs.retain(|r| r.bounds().is_finite());
        }
        let stored = refs.len();
        let describe = |k: usize| TriangleBox { bounds: refs[k].bounds(), waste: refs[k].spare() };
        let budget = options.presplit_percent as f32 / 100.0;
        // The fragments, if any triangle is cut; else the build takes the references as they are.
        // Spatial splits where the scene has large triangles, else the pre-split.
        let kept = |k: u32| triangle(refs[k as usize].index());
        let fragments = spatial_cuts(stored, describe, kept, options.spatial_levels)
            .or_else(|| presplit_cuts(stored, describe, kept, budget));
        let cut = fragments.as_ref().is_some_and(|f| f.boxes.len() > stored);
        let options_wide = ConvertOptions { collapse: options.collapse };
        // The fragments' boxes and the triangle each names, if some were left out (else a
        // fragment names its kept index, which is then the triangle's).
        let (boxes, owners) = match fragments {
            Some(f) if all_kept => (Some(f.boxes), Some(f.owner)),
            Some(f) => (Some(f.boxes), Some(f.owner.iter().map(|&k| refs[k as usize].index()).collect())),
            None => (None, None),
        };
        let mut sink = Blocks { ids: owners.as_deref(), blocks: Vec::new(), leaf_ids: Vec::new() };
        // Wide nodes straight from the boxes: no binary tree in between.
        let (layout, bounds) = match boxes {
            Some(boxes) => {
                drop(refs);
                build_wide(&options.builder, &boxes, options_wide, &mut sink)
            }
            None => build_wide_refs(&options.builder, refs, options_wide, &mut sink),
        };
        let blocks = sink.fill(&triangle);
        TriangleBvh {
            nodes: layout.nodes,
            blocks,
            depth: layout.depth,
            bounds,
            stored,
            count,
            cut,
            options,
            built_sah_cost: None,
            isa: Isa::best(),
        }
    }

    /// The instruction set queries run with.
    pub fn isa(&self) -> Isa {
        self.isa
    }

    /// Runs queries with `isa` from now on, if the processor has it (for tests and measurements:
    /// every instruction set gives the same answers).
    pub fn set_isa(&mut self, isa: Isa) -> Result<(), IsaUnavailable> {
        if !isa.is_available() {
            return Err(IsaUnavailable(isa));
        }
        self.isa = isa;
        Ok(())
    }

    /// The box around every stored triangle.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The nodes (the root is node 0).
    pub fn nodes(&self) -> &[WideNode] {
        &self.nodes
    }

    /// The triangle blocks, leaf after leaf.
    pub fn blocks(&self) -> &[TriBlock] {
        &self.blocks
    }

    /// Wide nodes on the longest path from the root to a leaf.
    pub fn depth(&self) -> u32 {
        self.depth
    }

    /// The closest triangle hit within the ray's interval: `t`, the triangle's index and the
    /// barycentric weights `(u, v)` of its second and third vertices. Of two triangles hit at
    /// the same `t`, the lower index wins.
    #[inline]
    pub fn closest_hit<C: Counters>(&self, ray: &Ray, counters: &mut C) -> Option<Hit> {
        self.closest_hit_filtered(ray, counters, NoFilter)
    }

    /// Whether any triangle is hit within the ray's interval (shadow rays).
    #[inline]
    pub fn any_hit<C: Counters>(&self, ray: &Ray, counters: &mut C) -> bool {
        self.any_hit_filtered(ray, counters, NoFilter)
    }

    /// [`TriangleBvh::closest_hit`] among the hits `filter` accepts (see
    /// [`crate::accel::interface::filter`]).
    ///
    /// ```
    /// use englobe::{Hit, NoCount, Ray, TriangleBvh, Vec3};
    ///
    /// let near = [Vec3::ZERO, Vec3::X, Vec3::Y];
    /// let bvh = TriangleBvh::from_triangles(&[near, near.map(|v| v - Vec3::Z)]);
    /// let ray = Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z);
    /// let hit = bvh.closest_hit_filtered(&ray, &mut NoCount, |h: &Hit| h.prim != 0).expect("the far one");
    /// assert_eq!((hit.prim, hit.t), (1, 2.0));
    /// ```
    #[inline]
    pub fn closest_hit_filtered<C: Counters, F: HitFilter<Hit>>(
        &self,
        ray: &Ray,
        counters: &mut C,
        filter: F,
    ) -> Option<Hit> {
        if !ray.is_valid() {
            return None;
        }
        self.closest_hit_of_valid(ray, counters, filter)
    }

    /// [`TriangleBvh::closest_hit_filtered`] of a ray the caller checked with [`Ray::is_valid`]
    /// (a world query checks once for all its structures).
    #[inline]
    pub(crate) fn closest_hit_of_valid<C: Counters, F: HitFilter<Hit>>(
        &self,
        ray: &Ray,
        counters: &mut C,
        filter: F,
    ) -> Option<Hit> {
        debug_assert!(ray.is_valid());
        if self.nodes.is_empty() {
            return None;
        }
        // The root's box first: a ray that passes beside it costs no more.
        counters.box_tests(1);
        if !self.may_enter(ray) {
            return None;
        }
        let node_ray = NodeRay::new(ray);
        triangle_leaves::closest_hit(&self.blocks, ray, ray.t_max, filter, |leaves| {
            dispatch::closest(self.isa, &self.nodes, self.depth, 0, &node_ray, leaves, counters)
        })
    }

    /// [`TriangleBvh::any_hit`] counting only the hits `filter` accepts.
    #[inline]
    pub fn any_hit_filtered<C: Counters, F: HitFilter<Hit>>(&self, ray: &Ray, counters: &mut C, filter: F) -> bool {
        ray.is_valid() && self.any_hit_of_valid(ray, counters, filter)
    }

    /// Whether `ray` may reach the tree: its origin inside the tree's box (then the root's test
    /// decides, at no extra cost: the rays of a scene seen from inside, shadow rays and bounces
    /// start there), or its slab test of the box ([`may_enter`]) passed. Never no where a node
    /// test would say yes.
    #[inline(always)]
    pub(super) fn may_enter(&self, ray: &Ray) -> bool {
        self.bounds.contains_point(ray.origin_a()) || may_enter(&self.bounds, ray, reach(ray.t_max))
    }

    /// Size and shape: wide nodes, leaves, depth, stored triangles and bytes. The leaf sizes count
    /// triangles per leaf.
    pub fn stats(&self) -> StructureStats {
        let mut leaf_sizes = [0; LEAF_SIZE_BUCKETS];
        let (mut leaves, mut refs) = (0, 0);
        for node in &self.nodes {
            for slot in 0..super::node::WIDTH {
                let c = node.children[slot];
                if c != super::node::EMPTY && super::node::is_leaf(c) {
                    let first = super::node::index_of(c) as usize;
                    let tris: u32 =
                        self.blocks[first..first + node.counts[slot] as usize].iter().map(TriBlock::used).sum();
                    leaf_sizes[(tris as usize).clamp(1, LEAF_SIZE_BUCKETS) - 1] += 1;
                    leaves += 1;
                    refs += tris as usize;
                }
            }
        }
        StructureStats {
            nodes: self.nodes.len(),
            leaves,
            depth: self.depth as usize,
            // A cut triangle counts once per leaf holding it.
            prim_refs: refs,
            memory_bytes: std::mem::size_of::<Self>()
                + std::mem::size_of_val(self.nodes.as_slice())
                + std::mem::size_of_val(self.blocks.as_slice()),
            sah_cost: None,
            leaf_sizes,
        }
    }
}
