//! Pre-splitting large triangles before the build, so that a long thin or diagonal triangle no
//! longer stretches one box across half the scene.
//!
//! A BVH bounds whole primitives, and a triangle whose box is much larger than the triangle (a
//! wall seen corner to corner, a long diagonal strut, a floor slab made of two triangles) makes
//! every node above it large: rays visit nodes that the triangle itself is far from. Spatial
//! splits fix this during the build (Stich, Friedrich and Dietrich 2009, "Spatial Splits in
//! Bounding Volume Hierarchies"); pre-splitting gets most of their benefit before it, with the
//! ordinary binned SAH builder unchanged: Karras and Aila (2013), "Fast Parallel Construction of
//! High-Quality Bounding Volume Hierarchies", section 5, which Embree's builders also apply
//! (a pre-split factor of 1.2).
//!
//! * **Which triangles.** Each triangle's priority is the surface area its box wastes: the box's
//!   area less the area the triangle's own projections cover. A budget of extra references (a
//!   fraction of the triangle count) is shared out in proportion to priority, so only the worst
//!   triangles are split, each into at most [`MAX_PIECES`] pieces. A triangle is a candidate only
//!   if its box wastes at least [`MIN_WASTE_SHARE`] of the scene box's area: a triangle small
//!   against the scene sits in small nodes, among neighbours whose boxes cover what its own box
//!   wastes, and cutting it costs the build a reference for nothing a ray would notice. On the
//!   ogre (an even mesh of 124 000 triangles) the budget made 16.4 % more references without
//!   that floor, 0.1 % with it: the build runs 25 % fewer instructions and the rays -1 % to +2 %
//!   more. The Sponza keeps nearly all its cuts (14.5 % more references instead of 14.9 %): its
//!   walls and floors are large against the atrium.
//! * **Where to cut.** A piece is cut across the longest axis of its box, at the coarsest plane
//!   of a power-of-two grid over the scene's box that crosses it: the planes a top-down build is
//!   likely to split at, so that pieces fall cleanly on both sides of nodes (Karras and Aila's
//!   choice). Each side is the piece's polygon cut by the plane (Sutherland and Hodgman's
//!   clipping, in `f64`, bounds rounded outward: a fragment's box always holds its part of the
//!   triangle).
//!
//! The build then sees fragments: boxes, each naming its triangle. A triangle may end up in
//! several leaves; the ray queries stay exact (each leaf tests the whole triangle, and the same
//! triangle always gives the same answer), a leaf never holds one triangle twice, and the queries
//! that list triangles report each once.

use glam::Vec3;

use crate::Aabb;
use crate::accel::MAX_PRIMITIVES;
use crate::accel::bvh::build::parallel::collect_indexed;
use crate::shapes::clip::Polygon;

/// Most pieces one triangle is cut into.
pub const MAX_PIECES: usize = 16;

/// The least area a triangle's box must waste, as a share of the scene box's surface area, for
/// the triangle to be cut (a box wasting 1/2048 of the scene's area: a square about 1/45 of the
/// scene's side). Chosen on the bunny, the ogre and the Sponza: see the module's documentation.
pub const MIN_WASTE_SHARE: f32 = 1.0 / 2048.0;

/// Triangles per task in the presplit's passes over all of them.
const CHUNK: usize = 1 << 14;

/// The boxes the build sees and, for each, the triangle (an index into the caller's list) it
/// belongs to.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Fragments {
    /// One box per fragment.
    pub boxes: Vec<Aabb>,
    /// `owner[i]` is the triangle of fragment `i`.
    pub owner: Vec<u32>,
}

/// A triangle as the presplit sees it: its box, and the surface area the box wastes (the box's
/// area less twice the triangle's projected areas on the three axis planes: what a box could not
/// avoid covering). Made where the caller fetches the triangles for their boxes anyway, so that
/// the presplit does not fetch every one a second time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleBox {
    /// The triangle's box.
    pub bounds: Aabb,
    /// The area the box wastes.
    pub waste: f32,
}

impl TriangleBox {
    /// The box of triangle `v` and its waste. Inlined: the builds that call it once per triangle
    /// are generic over how triangles are fetched, so they are compiled in the caller's crate,
    /// where a plain function of this one is a call that LLVM cannot inline.
    #[inline]
    pub fn of(v: &[Vec3; 3]) -> Self {
        let bounds = Aabb::from_points(*v);
        let n = (v[1] - v[0]).cross(v[2] - v[0]).abs();
        TriangleBox { bounds, waste: (bounds.surface_area() - (n.x + n.y + n.z)).max(0.0) }
    }
}

/// Cuts triangles `triangle(i)` for `i` in `0..triangles.len()` (each described by
/// `triangles[i]`, its box finite and not empty) into fragments, with at most `budget *
/// triangles.len()` fragments more than triangles; only the triangles whose boxes waste at least
/// [`MIN_WASTE_SHARE`] of the scene's area are cut. The triangles are cut in parallel; the
/// fragments come in triangle order, whatever the threads.
pub fn presplit(triangles: &[TriangleBox], triangle: impl Fn(u32) -> [Vec3; 3] + Sync, budget: f32) -> Fragments {
    presplit_cuts(triangles.len(), |i| triangles[i], triangle, budget).unwrap_or_else(|| Fragments {
        boxes: collect_indexed(triangles.len(), CHUNK, |i| triangles[i].bounds),
        owner: collect_indexed(triangles.len(), CHUNK, |i| i as u32),
    })
}

/// [`presplit`] over `count` triangles described by `describe(i)` (however the caller holds
/// them), or `None` when it would cut no triangle: the fragments would then be the triangles' own
/// boxes, which a caller that has them need not copy (hundreds of megabytes on a scene of
/// millions of triangles).
pub fn presplit_cuts(
    count: usize,
    describe: impl Fn(usize) -> TriangleBox + Sync,
    triangle: impl Fn(u32) -> [Vec3; 3] + Sync,
    budget: f32,
) -> Option<Fragments> {
    // References stay within what a build may hold (its bins count them in `i32` lanes).
    let extra = ((budget.max(0.0) * count as f32) as usize).min(MAX_PRIMITIVES.saturating_sub(count));
    if extra == 0 {
        return None;
    }
    // The passes over every triangle go in fixed chunks, in parallel: the scene's box, the sum
    // and the list of the triangles to cut come out the same whatever the threads.
    let chunks = count.div_ceil(CHUNK);
    let chunk = |c: usize| c * CHUNK..((c + 1) * CHUNK).min(count);
    let sum = |(s, w): (Aabb, f64), (b, x): (Aabb, f64)| (s.union(&b), w + x);
    let (scene, total) = collect_indexed(chunks, 1, |c| {
        chunk(c).map(&describe).map(|t| (t.bounds, t.waste as f64)).fold((Aabb::EMPTY, 0.0), sum)
    })
    .into_iter()
    .fold((Aabb::EMPTY, 0.0), sum);
    if !(total > 0.0) || !scene.is_finite() {
        return None;
    }
    // The budget is shared in proportion to every triangle's waste; those below the floor take
    // no part of it.
    let share = extra as f64 / total;
    let floor = scene.surface_area() * MIN_WASTE_SHARE;
    let pieces = |i: usize| {
        let waste = describe(i).waste;
        if waste < floor { 1 } else { (1 + (waste as f64 * share) as usize).min(MAX_PIECES) }
    };
    let cut_ones: Vec<u32> =
        collect_indexed(chunks, 1, |c| chunk(c).filter(|&i| pieces(i) > 1).map(|i| i as u32).collect::<Vec<_>>())
            .concat();
    if cut_ones.is_empty() {
        return None;
    }
    let cut_boxes: Vec<Vec<Aabb>> = collect_indexed(cut_ones.len(), 64, |k| {
        let i = cut_ones[k];
        let mut out = Vec::with_capacity(pieces(i as usize));
        cut(&Polygon::triangle(triangle(i)), describe(i as usize).bounds, pieces(i as usize), &scene, &mut out);
        out
    });
    // The triangles left whole go in runs, between the cut ones' fragments.
    let mut out = Fragments { boxes: Vec::with_capacity(count + extra), owner: Vec::with_capacity(count + extra) };
    let mut whole_from = 0;
    for (&i, parts) in cut_ones.iter().zip(&cut_boxes) {
        out.boxes.extend((whole_from..i as usize).map(|k| describe(k).bounds));
        out.owner.extend(whole_from as u32..i);
        out.boxes.extend_from_slice(parts);
        out.owner.extend(std::iter::repeat_n(i, parts.len()));
        whole_from = i as usize + 1;
    }
    out.boxes.extend((whole_from..count).map(|k| describe(k).bounds));
    out.owner.extend(whole_from as u32..count as u32);
    Some(out)
}

/// The coarsest plane of the power-of-two grid over `scene` along `axis` strictly inside
/// `(lo, hi)`, if the grid has one within twenty levels.
fn grid_plane(scene: &Aabb, axis: usize, lo: f32, hi: f32) -> Option<f32> {
    let (origin, size) = (scene.min[axis], scene.max[axis] - scene.min[axis]);
    if !(size > 0.0) {
        return None;
    }
    let (a, b) = ((lo - origin) / size, (hi - origin) / size);
    for level in 1..=20 {
        let cells = (1u32 << level) as f32;
        // The first grid line past `a` at this level.
        let x = ((a * cells).floor() + 1.0) / cells;
        if x < b {
            let plane = origin + x * size;
            return (plane > lo && plane < hi).then_some(plane);
        }
    }
    None
}

/// Cuts `part`, a part of a triangle whose bounds are `b`, into about `pieces` fragments, pushing
/// each fragment's box.
fn cut(part: &Polygon, b: Aabb, pieces: usize, scene: &Aabb, out: &mut Vec<Aabb>) {
    let extent = b.extent();
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let Some(plane) = (pieces > 1).then(|| grid_plane(scene, axis, b.min[axis], b.max[axis])).flatten() else {
        out.push(b);
        return;
    };
    let (mut below, mut above) = (Polygon::empty(), Polygon::empty());
    part.split_into(axis, plane as f64, &mut below, &mut above);
    // Rounded outward, each side's bounds stay within the part's.
    let (lb, ab) = (below.bounds().intersection(&b), above.bounds().intersection(&b));
    if lb.is_empty() || ab.is_empty() {
        // The part only touches one side: nothing to cut.
        out.push(b);
        return;
    }
    // Pieces in proportion to each side's length along the cut axis.
    let share = (plane - b.min[axis]) / extent[axis];
    let on_left = ((pieces as f32 * share).round() as usize).clamp(1, pieces - 1);
    cut(&below, lb, on_left, scene, out);
    cut(&above, ab, pieces - on_left, scene, out);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The presplit's view of `tris`, and their boxes.
    fn described(tris: &[[Vec3; 3]]) -> (Vec<TriangleBox>, Vec<Aabb>) {
        let input: Vec<TriangleBox> = tris.iter().map(TriangleBox::of).collect();
        let boxes = input.iter().map(|t| t.bounds).collect();
        (input, boxes)
    }

    fn diagonal(n: usize) -> Vec<[Vec3; 3]> {
        // Long thin triangles along the diagonal of a unit cube, and small ones for a budget.
        let mut t: Vec<[Vec3; 3]> = (0..n)
            .map(|i| {
                let o = Vec3::splat(i as f32 * 0.01);
                [o, o + Vec3::splat(0.001), o + Vec3::new(0.002, 0.0, 0.0)]
            })
            .collect();
        t.push([Vec3::ZERO, Vec3::ONE, Vec3::new(1.0, 1.0, 0.99)]);
        t
    }

    #[test]
    fn the_wasteful_triangle_is_cut_and_its_pieces_cover_it() {
        let tris = diagonal(50);
        let (input, boxes) = described(&tris);
        let f = presplit(&input, |i| tris[i as usize], 0.2);
        let long = (tris.len() - 1) as u32;
        let pieces: Vec<Aabb> = f.owner.iter().zip(&f.boxes).filter(|(o, _)| **o == long).map(|(_, b)| *b).collect();
        assert!(pieces.len() >= 4, "{} pieces", pieces.len());
        assert!(f.boxes.len() <= tris.len() + 10);
        // The pieces together cover the whole triangle, each inside the triangle's box, and
        // their areas add up to much less than the box's.
        let union = pieces.iter().fold(Aabb::EMPTY, |u, p| u.union(p));
        assert_eq!(union, boxes[long as usize]);
        let area: f32 = pieces.iter().map(|p| p.surface_area()).sum();
        assert!(area < 0.5 * boxes[long as usize].surface_area(), "{area}");
        // Points sampled on the triangle lie in some piece.
        for k in 0..200 {
            let (a, b) = ((k % 17) as f32 / 17.0, (k / 17) as f32 / 12.0);
            let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
            let t = &tris[long as usize];
            let p = t[0] + (t[1] - t[0]) * a + (t[2] - t[0]) * b;
            assert!(pieces.iter().any(|q| q.contains_point(p)), "{p} in no piece");
        }
        // The small triangles are left whole.
        assert!((0..50u32).all(|i| f.owner.iter().filter(|&&o| o == i).count() == 1));
    }

    #[test]
    fn triangles_small_against_the_scene_are_never_cut() {
        // A 100 x 100 grid of small triangles, one in four thin and diagonal (its box wastes
        // 4.68, a flat one's 0.81): the budget alone would cut each diagonal one in two (4 000
        // extra references shared over the waste), but none wastes 1/2048 of the scene's area.
        let grid = |k: usize| Vec3::new((k % 100) as f32, (k / 100) as f32, 0.0);
        let mut tris: Vec<[Vec3; 3]> = (0..10_000)
            .map(|k| {
                let o = grid(k);
                if k % 4 == 0 {
                    [o, o + Vec3::new(0.9, 0.9, 0.9), o + Vec3::new(0.9, 0.8, 0.9)]
                } else {
                    [o, o + Vec3::new(0.9, 0.0, 0.0), o + Vec3::new(0.0, 0.9, 0.0)]
                }
            })
            .collect();
        let (input, boxes) = described(&tris);
        let total: f32 = input.iter().map(|t| t.waste).sum();
        let waste = input[0].waste;
        let scene = boxes.iter().fold(Aabb::EMPTY, |s, b| s.union(b));
        assert!(waste * 4_000.0 / total >= 1.0, "{waste} of {total}");
        assert!(waste < scene.surface_area() * MIN_WASTE_SHARE);
        let f = presplit(&input, |i| tris[i as usize], 0.4);
        assert_eq!(f.boxes, boxes);
        assert_eq!(presplit_cuts(input.len(), |i| input[i], |i| tris[i as usize], 0.4), None);
        // The same triangle grown to a fifth of the scene is cut.
        tris[0] = [Vec3::ZERO, Vec3::splat(20.0), Vec3::new(20.0, 18.0, 20.0)];
        let (input, _) = described(&tris);
        let f = presplit(&input, |i| tris[i as usize], 0.4);
        let pieces = f.owner.iter().filter(|&&o| o == 0).count();
        assert!(pieces > 1, "{pieces} pieces");
        assert!(f.owner[pieces..].iter().copied().eq(1..10_000));
    }

    #[test]
    fn a_box_wastes_what_the_triangle_does_not_cover() {
        // Half the unit square: the box's two faces have area 2, the triangle covers half.
        let t = TriangleBox::of(&[Vec3::ZERO, Vec3::X, Vec3::Y]);
        assert_eq!((t.bounds, t.waste), (Aabb::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0)), 1.0));
        // Tilted out of every axis plane: its projections cover half of each face pair.
        let t = TriangleBox::of(&[Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 1.0)]);
        assert_eq!(t.waste, 6.0 - 3.0);
    }

    #[test]
    fn no_budget_no_split() {
        let tris = diagonal(3);
        let (input, boxes) = described(&tris);
        let f = presplit(&input, |i| tris[i as usize], 0.0);
        assert_eq!(f.boxes, boxes);
        assert_eq!(f.owner, vec![0, 1, 2, 3]);
        assert_eq!(presplit_cuts(input.len(), |i| input[i], |i| tris[i as usize], 0.0), None);
    }

    #[test]
    fn cut_triangles_in_several_chunks_keep_the_others_whole_and_in_order() {
        // Small triangles over three chunks' worth, and large diagonal ones among them: at the
        // start, inside the second chunk and last.
        let n = 2 * CHUNK + 100;
        let large = [0, CHUNK + 7, n - 1];
        let tris: Vec<[Vec3; 3]> = (0..n)
            .map(|i| {
                let o = Vec3::new((i % 100) as f32, (i / 100 % 100) as f32, (i / 10_000) as f32);
                if large.contains(&i) {
                    [o, o + Vec3::splat(50.0), o + Vec3::new(50.0, 49.0, 50.0)]
                } else {
                    [o, o + Vec3::new(0.1, 0.0, 0.0), o + Vec3::new(0.0, 0.1, 0.0)]
                }
            })
            .collect();
        let (input, boxes) = described(&tris);
        let f =
            presplit_cuts(input.len(), |i| input[i], |i| tris[i as usize], 0.1).expect("the large triangles are cut");
        assert!(f.owner.is_sorted(), "fragments in triangle order");
        for i in 0..n {
            let (from, to) =
                (f.owner.partition_point(|&o| (o as usize) < i), f.owner.partition_point(|&o| o as usize <= i));
            let pieces = &f.boxes[from..to];
            if large.contains(&i) {
                assert!(pieces.len() > 1, "triangle {i}: {} pieces", pieces.len());
                assert_eq!(pieces.iter().fold(Aabb::EMPTY, |u, p| u.union(p)), boxes[i]);
            } else {
                assert_eq!(pieces, &boxes[i..=i], "triangle {i}");
            }
        }
    }

    #[test]
    fn grid_planes_are_the_coarsest_inside() {
        let scene = Aabb::new(Vec3::ZERO, Vec3::splat(8.0));
        assert_eq!(grid_plane(&scene, 0, 1.0, 7.0), Some(4.0));
        assert_eq!(grid_plane(&scene, 0, 4.5, 7.0), Some(6.0));
        assert_eq!(grid_plane(&scene, 1, 4.0, 4.9), Some(4.5));
        assert_eq!(grid_plane(&scene, 2, 4.0, 4.0), None);
    }
}
