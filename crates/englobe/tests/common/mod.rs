//! Shared by the cross-structure tests: one check that runs every structure of
//! [`AccelKind::ALL`] against brute force (the kd-tree both with the caller's clipping and with
//! plain boxes), the shared data folder and its meshes, (in [`rng`]) the tests' random
//! numbers and (in [`strategies`]) the proptest strategies several tests share.

#![allow(dead_code)]

pub mod rng;
pub mod strategies;

use std::path::PathBuf;

use englobe::accel::{ClipFn, Validate};
use englobe::{Aabb, Accel, AccelKind, AnyAccel, Hit, NoCount, PrimHit, Ray, TriangleMesh, Vec3, WorkCounts};

/// Relative tolerance on the closest hit's `t`.
pub const T_TOLERANCE: f32 = 1e-6;

/// Builds every structure over `boxes`, validates each one, and checks that each one
/// gives the same closest hit (same primitive, `t` within [`T_TOLERANCE`] relative) and the same
/// any-hit answer as brute force for every ray, with counting on and off. Returns the first
/// disagreement.
pub fn check_all_structures(
    boxes: &[Aabb],
    rays: &[Ray],
    intersect: impl Fn(u32, &Ray) -> Option<PrimHit> + Copy,
) -> Result<(), String> {
    check_all_structures_clipped(boxes, &|p, c| boxes[p as usize].intersection(c), rays, intersect)
}

/// [`check_all_structures`] with the structures that clip primitives to cells (the kd-tree) built
/// with `clip`, and once more with plain box clipping.
pub fn check_all_structures_clipped(
    boxes: &[Aabb],
    clip: ClipFn<'_>,
    rays: &[Ray],
    intersect: impl Fn(u32, &Ray) -> Option<PrimHit> + Copy,
) -> Result<(), String> {
    let expected = brute_force_answers(boxes, rays, intersect);
    let mut builds: Vec<(String, AnyAccel)> =
        AccelKind::ALL.iter().map(|&k| (k.to_string(), AnyAccel::build_with_clipper(k, boxes, clip))).collect();
    builds.push(("kdtree with box clipping".to_owned(), AnyAccel::build(AccelKind::KdTree, boxes)));
    builds.push(("grid with box clipping".to_owned(), AnyAccel::build(AccelKind::Grid, boxes)));
    for (kind, accel) in &builds {
        check_structure(kind, accel, boxes, clip, rays, &expected, intersect)?;
    }
    Ok(())
}

/// Brute force's closest hit and any-hit answer for every ray.
pub fn brute_force_answers(
    boxes: &[Aabb],
    rays: &[Ray],
    intersect: impl Fn(u32, &Ray) -> Option<PrimHit> + Copy,
) -> Vec<(Option<Hit>, bool)> {
    let brute = AnyAccel::build(AccelKind::None, boxes);
    rays.iter()
        .map(|r| {
            (
                brute.closest_hit(r, &mut NoCount, intersect),
                brute.any_hit(r, &mut NoCount, |i, r| intersect(i, r).is_some()),
            )
        })
        .collect()
}

/// Checks one built structure (`kind` names it in errors): its invariants (every structure's
/// [`Validate`]; grids built with `clip`), and its answers on `rays` against brute force's
/// `expected`, with counting on and off.
pub fn check_structure(
    kind: &str,
    accel: &AnyAccel,
    boxes: &[Aabb],
    clip: ClipFn<'_>,
    rays: &[Ray],
    expected: &[(Option<Hit>, bool)],
    intersect: impl Fn(u32, &Ray) -> Option<PrimHit> + Copy,
) -> Result<(), String> {
    let stats = accel.validate(boxes, Some(clip)).map_err(|e| format!("{kind}: {e}"))?;
    if stats != accel.stats() {
        return Err(format!("{kind}: the validator measured {stats:?}, the structure reports {:?}", accel.stats()));
    }
    for (ray, &(closest, any)) in rays.iter().zip(expected) {
        let got = accel.closest_hit(ray, &mut NoCount, intersect);
        same_hit(closest, got).map_err(|e| format!("{kind}: closest hit of {ray:?}: {e}"))?;
        let mut counts = WorkCounts::default();
        let counted = accel.closest_hit(ray, &mut counts, intersect);
        if counted != got {
            return Err(format!("{kind}: counting changed the closest hit of {ray:?}: {got:?} then {counted:?}"));
        }
        let got_any = accel.any_hit(ray, &mut NoCount, |i, r| intersect(i, r).is_some());
        if got_any != any {
            return Err(format!("{kind}: any hit of {ray:?}: brute force says {any}, {kind} says {got_any}"));
        }
        if closest.is_some() && !any {
            return Err(format!("brute force: a closest hit but no any hit for {ray:?}"));
        }
    }
    Ok(())
}

fn same_hit(expected: Option<Hit>, got: Option<Hit>) -> Result<(), String> {
    match (expected, got) {
        (None, None) => Ok(()),
        (Some(e), Some(g)) => {
            let tolerance = T_TOLERANCE * e.t.abs().max(f32::MIN_POSITIVE);
            if e.prim != g.prim || (e.t - g.t).abs() > tolerance {
                Err(format!("expected primitive {} at t = {}, got primitive {} at t = {}", e.prim, e.t, g.prim, g.t))
            } else {
                Ok(())
            }
        }
        (e, g) => Err(format!("expected {e:?}, got {g:?}")),
    }
}

/// The shared data folder (`shared/`, holding `scenes/`): `ENGLOBE_SHARED` if set, otherwise the
/// first ancestor of this crate that has a `shared/scenes` folder beside it. Panics (the test
/// fails) if there is none: the tests that need it must not pass silently without it.
pub fn shared_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("ENGLOBE_SHARED") {
        let dir = PathBuf::from(dir);
        assert!(dir.join("scenes").is_dir(), "ENGLOBE_SHARED={} has no scenes folder", dir.display());
        return dir;
    }
    let manifest = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    manifest.ancestors().map(|a| a.join("shared")).find(|s| s.join("scenes").is_dir()).unwrap_or_else(|| {
        panic!("no shared/scenes folder beside any ancestor of {}; set ENGLOBE_SHARED", manifest.display())
    })
}

/// A mesh of the shared data folder (path relative to it), all its objects in one mesh.
pub fn load_obj(relative: &str) -> TriangleMesh {
    let path = shared_dir().join(relative);
    let (models, _) = tobj::load_obj(&path, &tobj::GPU_LOAD_OPTIONS)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    for m in models {
        let base = positions.len() as u32;
        positions.extend(m.mesh.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])));
        triangles.extend(m.mesh.indices.chunks_exact(3).map(|t| [base + t[0], base + t[1], base + t[2]]));
    }
    TriangleMesh::new(positions, triangles).expect("a valid mesh")
}

/// A folded `n` x `n` grid of triangles sharing edges and vertices, with integer coordinates in
/// x and y and heights of 0, 0.5 and 1: rays along the axes through its vertices and edges hit
/// exactly on them.
pub fn folded_grid(n: usize) -> Vec<[Vec3; 3]> {
    let p = |i: usize, j: usize| Vec3::new(i as f32, j as f32, ((i + j) % 3) as f32 * 0.5);
    let mut tris = Vec::new();
    for i in 0..n {
        for j in 0..n {
            tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
            tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
        }
    }
    tris
}
