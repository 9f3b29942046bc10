//! The tests' random numbers: one generator, PCG32 (`rand_pcg::Pcg32`, the renderer's too),
//! seeded with [`SeedableRng::seed_from_u64`], so that a failing case reproduces from its seed on
//! every machine. The helpers are the samplings several tests share.

use englobe::{Aabb, Ray, Vec3};
pub use rand::RngExt;
use rand::SeedableRng;
pub use rand_pcg::Pcg32;

/// The tests' generator, started from `seed`.
pub fn seeded(seed: u64) -> Pcg32 {
    Pcg32::seed_from_u64(seed)
}

/// Uniform in `[0, 1)^3`.
pub fn unit_vec3(rng: &mut Pcg32) -> Vec3 {
    Vec3::new(rng.random(), rng.random(), rng.random())
}

/// Uniform in the cube `[-1, 1)^3`.
pub fn in_cube(rng: &mut Pcg32) -> Vec3 {
    unit_vec3(rng) * 2.0 - 1.0
}

/// Uniform in `bounds`.
pub fn in_box(rng: &mut Pcg32, bounds: &Aabb) -> Vec3 {
    bounds.min + bounds.extent() * unit_vec3(rng)
}

/// A unit direction: a point uniform in the cube `[-1, 1)^3`, normalised (`+x` for the centre).
/// Denser towards the cube's corners than uniform on the sphere, which the tests do not need.
pub fn cube_direction(rng: &mut Pcg32) -> Vec3 {
    in_cube(rng).normalize_or(Vec3::X)
}

/// A ray from a random point of the sphere around `bounds` (centred on it, its radius the box's
/// diagonal) towards a uniform point of the box: rays from all around, about half of which hit
/// what fills the box.
pub fn ray_into_box(rng: &mut Pcg32, bounds: &Aabb) -> Ray {
    let origin = bounds.center() + cube_direction(rng) * bounds.extent().length();
    let target = in_box(rng, bounds);
    Ray::new(origin, target - origin)
}
