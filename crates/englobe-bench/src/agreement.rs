//! Agreement: every library's answers, taken from the very runs that are timed, are compared
//! with englobe's brute force (every ray against every triangle with the watertight test) on an
//! evenly spaced sample of each ray set.
//!
//! * Closest hit: both must hit or both miss, and the distances must agree within
//!   `1e-4 * max(t, r)` (`r` the bounding sphere's radius). Libraries use different triangle
//!   tests (watertight, Möller-Trumbore, Embree's), whose distances differ in the last bits; the
//!   floor at `1e-4 * r` covers short bounce rays, whose distance error follows the scene's
//!   coordinates rather than `t`. The triangle id is not compared: two triangles sharing the hit
//!   edge, or coplanar ones, are equally right.
//! * Any hit: the same yes or no as "brute force found a closest hit".
//!
//! Only a watertight test is guaranteed never to let a ray through the shared edge of two
//! triangles; the others may, on a set of rays of near-zero measure, and may differ on rays that
//! graze a silhouette. Such rays are rare (none is expected in 10 000), so a library passes when
//! at most a fraction `tolerance` (0.1 % by default, at least one ray) of a sample disagrees: a
//! real defect (a lost subtree, a wrong interval, a stale `t`) shows up as many more.

use rayon::prelude::*;

use englobe::{AccelKind, NoCount, Object, World};

use crate::library::{BenchRay, RayResult};
use crate::scene::BenchScene;

/// Relative distance tolerance.
pub const DISTANCE_TOLERANCE: f32 = 1e-4;
/// Fraction of a sample allowed to disagree, by default.
pub const DEFAULT_MISMATCH_TOLERANCE: f64 = 1e-3;

/// Brute force's answers on a sample of one ray set.
#[derive(Clone, Debug)]
pub struct Reference {
    /// Indices of the sampled rays in the set.
    pub indices: Vec<usize>,
    /// Brute force's closest hit for each sampled ray.
    pub closest: Vec<RayResult>,
    /// The scene's bounding radius (the distance tolerance's floor).
    pub scale: f32,
}

/// How many sampled rays to check: at most `max_rays`, and no more than `budget` ray/triangle
/// tests in all, but at least 100 (or the whole set if smaller).
pub fn sample_size(set_len: usize, triangles: usize, max_rays: usize, budget: f64) -> usize {
    let by_budget = (budget / triangles.max(1) as f64) as usize;
    max_rays.min(by_budget).max(100).min(set_len)
}

/// `n` indices spread evenly over `0..len`.
pub fn sample_indices(len: usize, n: usize) -> Vec<usize> {
    (0..n).map(|i| (i as u128 * len as u128 / n as u128) as usize).collect()
}

/// Brute force's closest hits on `n` rays of `rays` (in rayon's current pool).
pub fn reference(scene: &BenchScene, rays: &[BenchRay], n: usize) -> anyhow::Result<Reference> {
    let world = World::build(vec![Object::Mesh(scene.mesh.clone())], AccelKind::None)?;
    let indices = sample_indices(rays.len(), n);
    let closest = indices
        .par_iter()
        .map(|&i| match world.closest_hit(&rays[i].to_englobe(), &mut NoCount) {
            Some(h) => RayResult::hit(h.t, h.prim),
            None => RayResult::MISS,
        })
        .collect();
    Ok(Reference { indices, closest, scale: scene.bounding_sphere().1 })
}

/// Disagreements of one library on one sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Mismatches {
    /// Rays compared.
    pub checked: usize,
    /// One hit where the other missed.
    pub hit_miss: usize,
    /// Both hit, at distances further apart than the tolerance.
    pub distance: usize,
}

impl Mismatches {
    /// All disagreements.
    pub fn total(&self) -> usize {
        self.hit_miss + self.distance
    }

    /// Whether they are within `tolerance` (a fraction of the rays checked, at least one ray).
    pub fn acceptable(&self, tolerance: f64) -> bool {
        self.total() as f64 <= (tolerance * self.checked as f64).max(1.0)
    }
}

/// Whether two hit distances agree.
pub fn distances_agree(t: f32, reference: f32, scale: f32) -> bool {
    (t - reference).abs() <= DISTANCE_TOLERANCE * reference.max(scale)
}

/// Compares a library's closest hits (`results[i]` for ray `i` of the whole set) with brute force.
pub fn check_closest(reference: &Reference, results: &[RayResult]) -> Mismatches {
    let mut m = Mismatches { checked: reference.indices.len(), ..Mismatches::default() };
    for (&i, want) in reference.indices.iter().zip(&reference.closest) {
        let got = results[i];
        match (got.is_hit(), want.is_hit()) {
            (true, true) if !distances_agree(got.t, want.t, reference.scale) => m.distance += 1,
            (a, b) if a != b => m.hit_miss += 1,
            _ => {}
        }
    }
    m
}

/// Compares a library's any-hit answers with brute force.
pub fn check_any(reference: &Reference, results: &[bool]) -> Mismatches {
    let mut m = Mismatches { checked: reference.indices.len(), ..Mismatches::default() };
    for (&i, want) in reference.indices.iter().zip(&reference.closest) {
        if results[i] != want.is_hit() {
            m.hit_miss += 1;
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_are_spread_and_bounded() {
        assert_eq!(sample_indices(10, 5), vec![0, 2, 4, 6, 8]);
        assert_eq!(sample_size(1 << 20, 69_451, 10_000, 2e9), 10_000);
        assert_eq!(sample_size(1 << 20, 1_000_000, 10_000, 2e9), 2_000);
        assert_eq!(sample_size(1 << 20, 100_000_000, 10_000, 2e9), 100);
        assert_eq!(sample_size(50, 10, 10_000, 2e9), 50);
    }

    #[test]
    fn mismatches_are_classified() {
        let reference = Reference {
            indices: vec![0, 1, 2, 3],
            closest: vec![RayResult::hit(1.0, 0), RayResult::MISS, RayResult::hit(2.0, 1), RayResult::hit(3.0, 2)],
            scale: 1.0,
        };
        let got = [RayResult::hit(1.00005, 7), RayResult::hit(1.0, 0), RayResult::MISS, RayResult::hit(3.1, 2)];
        let m = check_closest(&reference, &got);
        assert_eq!(m, Mismatches { checked: 4, hit_miss: 2, distance: 1 });
        assert!(!m.acceptable(0.5));
        assert_eq!(check_any(&reference, &[true, false, true, true]).total(), 0);
        assert_eq!(check_any(&reference, &[false, true, true, true]).hit_miss, 2);
    }
}
