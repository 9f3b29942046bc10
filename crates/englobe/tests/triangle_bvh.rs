//! [`TriangleBvh`], the triangle fast path, against brute force with the scalar watertight test
//! (Woop, Benthin and Wald 2013): the same closest hit (triangle, `t`, barycentrics, bit for bit)
//! and the same any-hit answer, in every instruction set the processor has, with counting on and
//! off, one ray at a time and in packets. Random soups with degenerate triangles, axis-parallel rays through shared vertices and
//! edges, vertices shared by up to forty triangles, ties between copies, deep trees, and the
//! Stanford bunny.

mod common;

use common::load_obj;
use common::rng::{in_box, in_cube, ray_into_box, seeded};
use common::strategies::{point, triangle};
use englobe::accel::wide::Isa;
use englobe::shapes::{WatertightRay, intersect_triangle};
use englobe::{Hit, NoCount, Ray, TriangleBvh, Vec3, WorkCounts};
use proptest::prelude::*;

/// The closest hit by testing every triangle, ties to the lower index, and the any-hit answer.
fn brute(tris: &[[Vec3; 3]], ray: &Ray) -> (Option<Hit>, bool) {
    let w = WatertightRay::new(ray);
    let mut best: Option<Hit> = None;
    let mut any = false;
    for (i, [a, b, c]) in tris.iter().enumerate() {
        let t_max = best.map_or(ray.t_max, |h| h.t);
        if let Some(h) = intersect_triangle(&ray.with_range(ray.t_min, t_max), &w, *a, *b, *c) {
            any = true;
            if best.is_none_or(|b| h.t < b.t) {
                best = Some(Hit { t: h.t, prim: i as u32, u: h.u, v: h.v });
            }
        }
    }
    (best, any)
}

/// Checks `bvh` in every available instruction set against brute force on every ray; returns the
/// number of rays that hit.
fn check(tris: &[[Vec3; 3]], rays: &[Ray]) -> Result<usize, String> {
    check_built(TriangleBvh::from_triangles(tris), tris, rays)
}

/// [`check`] on a structure built over `tris` some other way.
fn check_built(mut bvh: TriangleBvh, tris: &[[Vec3; 3]], rays: &[Ray]) -> Result<usize, String> {
    let expected: Vec<(Option<Hit>, bool)> = rays.iter().map(|r| brute(tris, r)).collect();
    for isa in Isa::available() {
        bvh.set_isa(isa).map_err(|e| e.to_string())?;
        for (ray, &(closest, any)) in rays.iter().zip(&expected) {
            let got = bvh.closest_hit(ray, &mut NoCount);
            if got != closest {
                return Err(format!("{isa}: closest hit of {ray:?}: brute force {closest:?}, TriangleBvh {got:?}"));
            }
            let counted = bvh.closest_hit(ray, &mut WorkCounts::default());
            if counted != got {
                return Err(format!("{isa}: counting changed the closest hit of {ray:?}"));
            }
            let got_any = bvh.any_hit(ray, &mut NoCount);
            if got_any != any {
                return Err(format!("{isa}: any hit of {ray:?}: brute force {any}, TriangleBvh {got_any}"));
            }
        }
        // The same rays in packets of sixteen consecutive ones.
        let mut hits = vec![None; rays.len()];
        let mut mask = vec![false; rays.len()];
        bvh.closest_hit_packet(rays, &mut hits, &mut NoCount).map_err(|e| e.to_string())?;
        bvh.any_hit_packet(rays, &mut mask, &mut NoCount).map_err(|e| e.to_string())?;
        for ((ray, &(closest, any)), (got, got_any)) in rays.iter().zip(&expected).zip(hits.iter().zip(&mask)) {
            if *got != closest || *got_any != any {
                return Err(format!(
                    "{isa}: packet of {ray:?}: brute force {closest:?} {any}, TriangleBvh {got:?} {got_any}"
                ));
            }
        }
    }
    Ok(expected.iter().filter(|e| e.0.is_some()).count())
}

/// Directions: random, or along an axis with zeros of either sign.
fn direction() -> impl Strategy<Value = Vec3> {
    let axis = (0usize..3, prop::bool::ANY, prop::bool::ANY).prop_map(|(axis, negative, negative_zeros)| {
        let mut d = Vec3::splat(if negative_zeros { -0.0 } else { 0.0 });
        d[axis] = if negative { -1.0 } else { 1.0 };
        d
    });
    prop_oneof![2 => point(), 1 => axis].prop_filter("a direction", |d| *d != Vec3::ZERO)
}

/// Origin, direction, a vertex to aim at instead (triangle, vertex), `t_min`, `t_max`.
type RaySpec = (Vec3, Vec3, Option<(usize, usize)>, f32, f32);

/// Rays from anywhere, or aimed exactly at a vertex of one of the triangles, over the whole line
/// or a segment.
fn rays(tris: &[[Vec3; 3]], specs: &[RaySpec]) -> Vec<Ray> {
    specs
        .iter()
        .map(|&(o, d, aim, t0, t1)| {
            let d = match aim {
                Some((i, k)) if tris[i % tris.len()][k % 3] != o => tris[i % tris.len()][k % 3] - o,
                _ => d,
            };
            Ray::segment(o * 1.5, d, t0, t1)
        })
        .collect()
}

fn ray_spec() -> impl Strategy<Value = RaySpec> {
    let range =
        prop_oneof![3 => Just((0.0f32, f32::INFINITY)), 1 => (0.0f32..3.0, 0.0f32..6.0).prop_map(|(a, b)| (a, a + b))];
    (point(), direction(), prop::option::of((0usize..1000, 0usize..3)), range)
        .prop_map(|(o, d, aim, (t0, t1))| (o, d, aim, t0, t1))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn random_soups_agree_with_brute_force(
        tris in prop::collection::vec(triangle(), 1..300),
        specs in prop::collection::vec(ray_spec(), 1..60),
    ) {
        let rays = rays(&tris, &specs);
        check(&tris, &rays).map_err(TestCaseError::fail)?;
    }
}

#[test]
fn axis_parallel_rays_through_shared_vertices_and_edges() {
    // A folded grid of triangles sharing edges and vertices, with integer coordinates: rays along
    // the axes through vertices and edges hit exactly on them.
    let n = 12;
    let tris = common::folded_grid(n);
    let mut rays = Vec::new();
    for i in 0..=2 * n {
        for j in 0..=2 * n {
            let (x, y) = (i as f32 * 0.5, j as f32 * 0.5);
            for (o, d) in [
                (Vec3::new(x, y, 5.0), Vec3::new(0.0, -0.0, -1.0)),
                (Vec3::new(x, y, -5.0), Vec3::Z),
                (Vec3::new(-1.0, y, x * 0.1), Vec3::X),
                (Vec3::new(x, n as f32 + 1.0, 0.5), -Vec3::Y),
            ] {
                rays.push(Ray::new(o, d));
            }
        }
    }
    let hits = check(&tris, &rays).unwrap();
    // Watertight: every vertical ray inside the grid's footprint hits.
    let vertical = rays.iter().filter(|r| r.dir().x == 0.0 && r.dir().y == 0.0).count();
    assert!(hits >= vertical, "{hits} hits, {vertical} vertical rays");
}

#[test]
fn vertices_shared_by_many_triangles() {
    // Fans of 6 to 40 triangles around vertices at several heights, one above another: a ray
    // through the shared vertices leaves every lane of their blocks to the scalar test, more lanes
    // than a query notes in its first walk, so the walks that follow it decide them. Rays down
    // through the vertices (whole line and short segments that stop before some fans, for any-hit
    // queries that find nothing), slanted rays aimed at them, and rays beside them.
    let mut tris = Vec::new();
    for (f, n) in [6, 12, 40, 23, 9].into_iter().enumerate() {
        let centre = Vec3::new(0.25 * f as f32, 0.0, -(f as f32));
        for k in 0..n {
            let at = |i: usize| {
                let a = i as f32 * std::f32::consts::TAU / n as f32;
                centre + Vec3::new(a.cos(), a.sin(), 0.1 * (i % 3) as f32)
            };
            tris.push([centre, at(k), at(k + 1)]);
        }
    }
    let mut rays = Vec::new();
    for f in 0..5 {
        let centre = Vec3::new(0.25 * f as f32, 0.0, -(f as f32));
        for t_max in [f32::INFINITY, 0.5, 1.5] {
            rays.push(Ray::segment(centre + Vec3::Z, -Vec3::Z, 0.0, t_max));
        }
        for o in [Vec3::new(2.0, 1.0, 3.0), Vec3::new(-1.5, -2.0, 1.0), Vec3::new(0.5, 3.0, -7.0)] {
            rays.push(Ray::new(o, centre - o));
            rays.push(Ray::segment(o, centre - o, 0.0, 0.999));
            rays.push(Ray::new(o, centre + Vec3::new(0.01, 0.02, 0.0) - o));
        }
    }
    let hits = check(&tris, &rays).unwrap();
    assert!(hits > rays.len() / 2, "{hits} of {} rays hit", rays.len());
}

#[test]
fn degenerate_triangles_are_never_hit_and_never_stored() {
    let tris = vec![
        [Vec3::ZERO, Vec3::X, Vec3::X * 2.0],
        [Vec3::Y, Vec3::Y, Vec3::Z],
        [Vec3::ZERO, Vec3::X, Vec3::Y],
        [Vec3::splat(f32::NAN), Vec3::X, Vec3::Y],
        [Vec3::ONE; 3],
    ];
    let bvh = TriangleBvh::from_triangles(&tris);
    assert_eq!(bvh.stats().prim_refs, 1);
    let rays: Vec<Ray> =
        [Vec3::new(0.5, 0.0, 1.0), Vec3::new(0.2, 0.2, 1.0), Vec3::new(0.0, 1.0, 0.5), Vec3::ONE + Vec3::Z]
            .into_iter()
            .flat_map(|o| {
                [Ray::new(o, -Vec3::Z), Ray::new(o - Vec3::Y * 2.0, Vec3::Y), Ray::new(o + Vec3::X, -Vec3::X)]
            })
            .collect();
    assert!(check(&tris, &rays).unwrap() > 0);
    for r in &rays {
        assert!(bvh.closest_hit(r, &mut NoCount).is_none_or(|h| h.prim == 2), "{r:?}");
    }
    let none = [[Vec3::ZERO, Vec3::X, Vec3::X]; 10];
    let empty = TriangleBvh::from_triangles(&none);
    assert_eq!(empty.stats().prim_refs, 0);
    assert_eq!(check(&none, &rays).unwrap(), 0);
    assert_eq!(check(&[], &rays).unwrap(), 0);
}

#[test]
fn copies_of_one_triangle_tie_to_the_lowest_index() {
    let t = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let mut tris = vec![[Vec3::new(5.0, 5.0, 5.0), Vec3::new(6.0, 5.0, 5.0), Vec3::new(5.0, 6.0, 5.0)]; 3];
    tris.extend(std::iter::repeat_n(t, 40));
    let ray = Ray::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z);
    check(&tris, &[ray]).unwrap();
    assert_eq!(TriangleBvh::from_triangles(&tris).closest_hit(&ray, &mut NoCount).map(|h| h.prim), Some(3));
}

#[test]
fn deep_trees_of_nested_triangles() {
    // Nested triangles shrinking geometrically around one point: the SAH separates them a few at
    // a time, so the tree is deep and every ray near the centre walks down all of it.
    let tris: Vec<[Vec3; 3]> = (0..1500)
        .map(|i| {
            let s = 0.96f32.powi(i);
            [Vec3::new(-s, -s, s * 0.1), Vec3::new(s, -s, s * 0.1), Vec3::new(0.0, s, s * 0.1)]
        })
        .collect();
    let bvh = TriangleBvh::from_triangles(&tris);
    let rays: Vec<Ray> = (0..200)
        .map(|k| {
            let x = (k as f32 * 0.37).sin() * 0.5;
            [Ray::new(Vec3::new(x, 0.0, -1.0), Vec3::Z), Ray::new(Vec3::new(x, 0.01, 10.0), -Vec3::Z)][k % 2]
        })
        .collect();
    let hits = check(&tris, &rays).unwrap();
    assert!(hits > 100, "{hits}");
    assert!(bvh.depth() > 16, "depth {}", bvh.depth());
}

#[test]
fn stanford_bunny_in_every_instruction_set() {
    let mesh = load_obj("scenes/meshes/bunny/stanford-bunny.obj");
    let tris: Vec<[Vec3; 3]> = (0..mesh.len() as u32).map(|i| mesh.triangle(i).vertices).collect();
    let bounds = mesh.bounds();
    let (centre, extent) = (bounds.center(), bounds.extent());
    let mut rng = seeded(0x9e37_79b9_7f4a_7c15);
    let mut rays = Vec::new();
    for _ in 0..1500 {
        rays.push(ray_into_box(&mut rng, &bounds));
        // Rays from inside the mesh's box, in every direction (some start inside the bunny).
        let inside = in_box(&mut rng, &bounds);
        rays.push(Ray::new(inside, in_cube(&mut rng) * 0.5));
    }
    for axis in 0..3 {
        for i in 0..10 {
            let mut o = centre + extent * ((i as f32 + 0.5) / 10.0 - 0.5);
            o[axis] = bounds.min[axis] - 1.0;
            let mut d = Vec3::splat(0.0);
            d[axis] = 1.0;
            rays.push(Ray::new(o, d));
        }
    }
    let hits = check(&tris, &rays).unwrap();
    assert!(hits * 3 > rays.len(), "only {hits} of {} rays hit", rays.len());

    // Work: a small fraction of brute force's exact tests.
    let bvh = TriangleBvh::from_triangles(&tris);
    let mut counts = WorkCounts::default();
    for r in &rays {
        bvh.closest_hit(r, &mut counts);
    }
    let brute_tests = (tris.len() * rays.len()) as u64;
    assert!(counts.exact_tests * 500 < brute_tests, "{} exact tests, brute force {brute_tests}", counts.exact_tests);
}

/// Ten rays into each of `struts`, from random points around `bounds`, aimed at points inside the
/// strut along its length (crossing the presplit's cuts), not at a vertex or on an edge, where an
/// isolated triangle is hit or missed by a rounding.
fn rays_into_struts<'a>(
    rng: &mut rand_pcg::Pcg32,
    struts: impl IntoIterator<Item = &'a [Vec3; 3]>,
    bounds: &englobe::Aabb,
) -> Vec<Ray> {
    let mut rays = Vec::new();
    for t in struts {
        for k in 0..10 {
            let s = (k as f32 + 0.5) / 10.0;
            let target = t[0] + (t[1] - t[0]) * s + (t[2] - t[1]) * (0.5 * s);
            let origin = in_box(rng, bounds) * 1.5;
            rays.push(Ray::new(origin, target - origin));
        }
    }
    rays
}

/// Struts cut by the presplit among triangles the build leaves out (zero areas, a NaN): the
/// fragments name their triangles by the indices the caller gave, not by their places among the
/// triangles kept, and every query stays brute force's.
#[test]
fn cut_triangles_among_left_out_ones_keep_their_indices() {
    use englobe::Aabb;
    use englobe::accel::Validate;

    let mut rng = seeded(43);
    let mut tris: Vec<[Vec3; 3]> = Vec::new();
    let mut struts = Vec::new();
    for k in 0..460 {
        match k % 23 {
            0 => tris.push([Vec3::splat(k as f32 * 0.01); 3]),
            1 => tris.push([Vec3::new(f32::NAN, 0.0, 0.0), Vec3::X, Vec3::Y]),
            2 => {
                let (a, b) = (in_cube(&mut rng) * 4.0, in_cube(&mut rng) * 4.0);
                struts.push(tris.len());
                tris.push([a, b, b + in_cube(&mut rng) * 0.1]);
            }
            _ => {
                let c = in_cube(&mut rng) * 4.0;
                tris.push([c, c + in_cube(&mut rng) * 0.05, c + in_cube(&mut rng) * 0.05]);
            }
        }
    }
    let bvh = TriangleBvh::from_triangles(&tris);
    let boxes: Vec<Aabb> = tris.iter().map(|t| Aabb::from_points(*t)).collect();
    let stats = bvh.validate(&boxes, None).expect("a valid structure");
    let kept = tris.len() - 2 * tris.len().div_ceil(23);
    assert!(stats.prim_refs > kept + 10, "{} references for {kept} triangles kept: nothing was cut", stats.prim_refs);

    let bounds = boxes.iter().filter(|b| b.is_finite()).fold(Aabb::EMPTY, |b, t| b.union(t));
    let mut rays: Vec<Ray> = (0..300).map(|_| ray_into_box(&mut rng, &bounds)).collect();
    rays.extend(rays_into_struts(&mut rng, struts.iter().map(|&i| &tris[i]), &bounds));
    let hits = check(&tris, &rays).expect("agreement with brute force");
    assert!(hits > 150, "{hits} hits");
}

/// Long diagonal struts among small triangles: the build cuts the struts into pieces that lie in
/// several leaves (see `englobe::accel::wide::presplit` and `spatial`). The structure stays valid,
/// every query stays brute force's, and the box query still lists each triangle once.
#[test]
fn cut_triangles_are_found_once_and_exactly() {
    use englobe::Aabb;
    use englobe::accel::Validate;
    use englobe::accel::wide::TriangleBvhOptions;

    let mut rng = seeded(41);
    let tris = struts_among_small_triangles(&mut rng, 400, 30);
    let bvh = TriangleBvh::from_triangles(&tris);
    let boxes: Vec<Aabb> = tris.iter().map(|t| Aabb::from_points(*t)).collect();
    let stats = bvh.validate(&boxes, None).expect("a valid structure");
    assert!(
        stats.prim_refs > tris.len() + 20,
        "{} references for {} triangles: nothing was cut",
        stats.prim_refs,
        tris.len()
    );
    let whole = TriangleBvh::build_with(
        tris.len(),
        |i| tris[i as usize],
        TriangleBvhOptions { presplit_percent: 0, spatial_levels: 0, ..Default::default() },
    );
    assert_eq!(whole.stats().prim_refs, tris.len());

    // Rays at random, and rays aimed at points inside the struts (crossing the cuts): inside, not
    // at a vertex or on an edge, where an isolated triangle is hit or missed by a rounding.
    let bounds = boxes.iter().fold(Aabb::EMPTY, |b, t| b.union(t));
    let mut rays: Vec<Ray> = (0..400).map(|_| ray_into_box(&mut rng, &bounds)).collect();
    rays.extend(rays_into_struts(&mut rng, &tris[400..], &bounds));
    let hits = check(&tris, &rays).expect("agreement with brute force");
    assert!(hits > 300, "{hits} hits");

    box_queries_list_each_triangle_once(&bvh, &tris, &mut rng, &bounds);
}

/// Spatial splits alone (no pre-split): struts among small triangles are cut where the top
/// levels' splits are, every piece's box holds its part of the strut, and every query stays brute
/// force's, each triangle found once.
#[test]
fn spatial_splits_are_found_once_and_exactly() {
    use englobe::Aabb;
    use englobe::accel::Validate;
    use englobe::accel::wide::TriangleBvhOptions;

    let mut rng = seeded(43);
    let tris = struts_among_small_triangles(&mut rng, 2000, 100);
    // No pre-split: every cut is the spatial splits'.
    let options = TriangleBvhOptions { spatial_levels: 6, presplit_percent: 0, ..Default::default() };
    let bvh = TriangleBvh::build_with(tris.len(), |i| tris[i as usize], options);
    let boxes: Vec<Aabb> = tris.iter().map(|t| Aabb::from_points(*t)).collect();
    let stats = bvh.validate(&boxes, None).expect("a valid structure");
    assert!(stats.prim_refs > tris.len() + 10, "{} references: nothing was cut", stats.prim_refs);
    assert!(stats.prim_refs <= tris.len() * 3 / 2, "{} references: over the budget", stats.prim_refs);

    let bounds = boxes.iter().fold(Aabb::EMPTY, |b, t| b.union(t));
    let mut rays: Vec<Ray> = (0..400).map(|_| ray_into_box(&mut rng, &bounds)).collect();
    rays.extend(rays_into_struts(&mut rng, &tris[2000..], &bounds));
    let hits = check_built(bvh.clone(), &tris, &rays).expect("agreement with brute force");
    assert!(hits > 300, "{hits} hits");

    box_queries_list_each_triangle_once(&bvh, &tris, &mut rng, &bounds);
}

/// `small` small triangles in a cube of side 8, then `struts` long thin ones across it.
fn struts_among_small_triangles(rng: &mut rand_pcg::Pcg32, small: usize, struts: usize) -> Vec<[Vec3; 3]> {
    let mut tris: Vec<[Vec3; 3]> = (0..small)
        .map(|_| {
            let c = in_cube(rng) * 4.0;
            [c, c + in_cube(rng) * 0.05, c + in_cube(rng) * 0.05]
        })
        .collect();
    for _ in 0..struts {
        let (a, b) = (in_cube(rng) * 4.0, in_cube(rng) * 4.0);
        tris.push([a, b, b + in_cube(rng) * 0.1]);
    }
    tris
}

/// Boxes at random in `bounds`: both box queries list exactly the triangles that overlap each,
/// every one once, however many pieces it was cut into.
fn box_queries_list_each_triangle_once(
    bvh: &TriangleBvh,
    tris: &[[Vec3; 3]],
    rng: &mut rand_pcg::Pcg32,
    bounds: &englobe::Aabb,
) {
    use englobe::shapes::triangle_overlaps_box;
    for _ in 0..50 {
        let (a, b) = (in_box(rng, bounds), in_box(rng, bounds));
        let query = englobe::Aabb::new(a.min(b), a.max(b));
        let expected: Vec<u32> =
            (0..tris.len() as u32).filter(|&i| triangle_overlaps_box(tris[i as usize], &query)).collect();
        assert_eq!(bvh.triangles_in_box(&query), expected);
        let mut listed = Vec::new();
        bvh.for_each_triangle_in_box(&query, |t| listed.push(t));
        listed.sort_unstable();
        assert_eq!(listed, expected, "a triangle listed twice or missed");
    }
}
