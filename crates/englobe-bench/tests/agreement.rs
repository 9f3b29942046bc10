//! The agreement check: every library this build has gives brute force's answers on the bunny,
//! and a deliberately wrong library is caught.

use std::path::Path;

use englobe_bench::agreement::{self, DEFAULT_MISMATCH_TOLERANCE, Reference};
use englobe_bench::measure::{Answers, Query, thread_pool, trace};
use englobe_bench::rays::{RayParams, RaySetKind};
use englobe_bench::registry::{BuildSettings, build_library};
use englobe_bench::run::generate_rays;
use englobe_bench::{BenchRay, BenchScene, Library, LibraryKind, RayResult, RaySets};
use englobe_scene::shared_data::shared_meshes_or_panic;

fn bunny_and_rays() -> (BenchScene, RaySets) {
    let meshes = shared_meshes_or_panic(Path::new(env!("CARGO_MANIFEST_DIR")));
    let scene = BenchScene::load("bunny", &meshes.join("bunny/stanford-bunny.obj"), None).unwrap();
    let sets = generate_rays(&scene, RayParams { resolution: 48, count: 2048, seed: 3 }, 2).unwrap();
    (scene, sets)
}

fn references(scene: &BenchScene, sets: &RaySets) -> Vec<(RaySetKind, Reference)> {
    RaySetKind::ALL.into_iter().map(|k| (k, agreement::reference(scene, sets.get(k), 400).unwrap())).collect()
}

/// Every check of one library: (closest, any) mismatches per ray set.
fn check(library: &dyn Library, sets: &RaySets, refs: &[(RaySetKind, Reference)]) -> Vec<(usize, usize)> {
    let pool = thread_pool(2).unwrap();
    refs.iter()
        .map(|(kind, reference)| {
            let rays = sets.get(*kind);
            let mut closest = Answers::new(Query::Closest, rays.len());
            let mut any = Answers::new(Query::Any, rays.len());
            pool.install(|| {
                trace(library, rays, &mut closest);
                trace(library, rays, &mut any);
            });
            let (Answers::Closest(c), Answers::Any(a)) = (&closest, &any) else { unreachable!() };
            let (mc, ma) = (agreement::check_closest(reference, c), agreement::check_any(reference, a));
            assert!(mc.checked == 400 && ma.checked == 400);
            (mc.total(), ma.total())
        })
        .collect()
}

#[test]
fn every_library_agrees_with_brute_force_on_the_bunny() {
    let (scene, sets) = bunny_and_rays();
    let refs = references(&scene, &sets);
    // The samples exercise both answers.
    for (kind, r) in &refs {
        let hits = r.closest.iter().filter(|h| h.is_hit()).count();
        assert!(hits > 20 && hits < 380, "{kind:?}: {hits} of 400 sampled rays hit");
    }
    let settings = BuildSettings { threads: 2, englobe: Default::default(), embree_robust: false };
    for kind in LibraryKind::available_kinds() {
        let library = thread_pool(2).unwrap().install(|| build_library(kind, &scene, &settings)).unwrap();
        for (i, (closest, any)) in check(library.as_ref(), &sets, &refs).into_iter().enumerate() {
            // At most 0.1 % of 400 rays (that is, one) may disagree; none is expected.
            let allowed = (DEFAULT_MISMATCH_TOLERANCE * 400.0f64).max(1.0) as usize;
            assert!(closest <= allowed && any <= allowed, "{kind} on {:?}: {closest} closest, {any} any", refs[i].0);
        }
    }
}

/// englobe, except that it loses every hit on a triangle whose index is a multiple of 3 (as a
/// structure that dropped a subtree would) and answers "no" to any-hit queries in the lower half
/// of the box.
struct Wrong(Box<dyn Library>, f32);

impl Library for Wrong {
    fn structure(&self) -> String {
        "deliberately wrong".into()
    }

    fn closest_hits(&self, rays: &[BenchRay], out: &mut [RayResult]) {
        self.0.closest_hits(rays, out);
        for o in out.iter_mut().filter(|o| o.is_hit() && o.prim % 3 == 0) {
            *o = RayResult::MISS;
        }
    }

    fn any_hits(&self, rays: &[BenchRay], out: &mut [bool]) {
        self.0.any_hits(rays, out);
        for (r, o) in rays.iter().zip(out) {
            *o &= r.origin.y > self.1;
        }
    }
}

#[test]
fn a_wrong_library_is_caught() {
    let (scene, sets) = bunny_and_rays();
    let refs = references(&scene, &sets);
    let settings = BuildSettings { threads: 2, englobe: Default::default(), embree_robust: false };
    let englobe = build_library(LibraryKind::Englobe, &scene, &settings).unwrap();
    let wrong = Wrong(englobe, scene.bounds().center().y);
    let results = check(&wrong, &sets, &refs);
    for ((kind, _), (closest, any)) in refs.iter().zip(results) {
        // About one hit in three is lost, and about half the any-hit answers in the lower half.
        assert!(closest > 5, "{kind:?}: only {closest} lost hits noticed");
        if *kind != RaySetKind::Primary {
            assert!(any > 10, "{kind:?}: only {any} wrong any-hit answers noticed");
        }
        let m = agreement::Mismatches { checked: 400, hit_miss: closest, distance: 0 };
        assert!(!m.acceptable(DEFAULT_MISMATCH_TOLERANCE));
    }
}
