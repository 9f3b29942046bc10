//! What the harness and a library under test share: the ray a library is given ([`BenchRay`]), the
//! answer of a closest-hit query ([`RayResult`]) and the [`Library`] trait each adapter of
//! `crate::adapters` implements. The bottom of the crate: it imports none of its other modules.

use englobe::Vec3;

/// One ray, as every library is given it: origin, direction, interval.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BenchRay {
    /// Origin.
    pub origin: Vec3,
    /// Smallest parameter that counts as a hit.
    pub t_min: f32,
    /// Unit direction.
    pub dir: Vec3,
    /// Largest parameter that counts as a hit.
    pub t_max: f32,
}

impl BenchRay {
    /// A ray over `0..=inf`.
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        BenchRay { origin, t_min: 0.0, dir, t_max: f32::INFINITY }
    }

    /// The point at parameter `t`.
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }

    /// The same ray as englobe's.
    pub fn to_englobe(&self) -> englobe::Ray {
        englobe::Ray::segment(self.origin, self.dir, self.t_min, self.t_max)
    }
}

/// The answer of a closest-hit query: the hit distance and the triangle, or a miss.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayResult {
    /// Hit distance (`inf` for a miss).
    pub t: f32,
    /// Triangle index in the scene's mesh ([`RayResult::MISS`]'s for a miss).
    pub prim: u32,
}

impl RayResult {
    /// No hit.
    pub const MISS: RayResult = RayResult { t: f32::INFINITY, prim: u32::MAX };

    /// A hit on triangle `prim` at `t`.
    pub fn hit(t: f32, prim: u32) -> Self {
        RayResult { t, prim }
    }

    /// Whether something was hit.
    pub fn is_hit(&self) -> bool {
        self.prim != u32::MAX
    }
}

/// A library, built and ready for queries. Queries take a slice so that a library can trace
/// several rays at once (packets); the harness hands each thread slices whose length is a
/// multiple of [`Library::packet_width`], except perhaps the last. A query never allocates.
pub trait Library: Send + Sync {
    /// What exactly is measured (structure, build settings, query function), for the CSV.
    fn structure(&self) -> String;

    /// The closest hit of each ray: `out[i]` for `rays[i]`.
    fn closest_hits(&self, rays: &[BenchRay], out: &mut [RayResult]);

    /// Whether each ray hits anything: `out[i]` for `rays[i]`.
    fn any_hits(&self, rays: &[BenchRay], out: &mut [bool]);

    /// Rays the library traces together (1 for single-ray queries).
    fn packet_width(&self) -> usize {
        1
    }
}
