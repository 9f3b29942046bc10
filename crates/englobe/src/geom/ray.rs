//! Rays: an origin, a direction and the interval `t_min..=t_max` of parameters that count as hits.
//!
//! The inverse direction is computed once per ray because every box test needs it. A zero
//! direction component (of either sign) gets an inverse of `+inf`, never `-inf`: the slab test in
//! [`crate::Aabb`] relies on that to treat a ray lying in a box face consistently (see there).

use glam::{Vec3, Vec3A, Vec4};

/// A ray `origin + t * dir` for `t` in the closed interval `t_min..=t_max`.
///
/// The direction need not be normalised; `t` is measured in units of its length. The interval is
/// closed so that two primitives hit at exactly the same `t` can be told apart by index, whatever
/// order a structure visits them in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    // Kept as aligned four-lane vectors: a ray is written by one function and read at once by
    // the next (a camera's or a shadow ray, then its query), and whole aligned lanes let each read
    // take its value straight from the write before it, where three-float fields straddled them.
    origin: Vec3A,
    dir: Vec3A,
    inv_dir: Vec3A,
    /// Smallest parameter that counts as a hit.
    pub t_min: f32,
    /// Largest parameter that counts as a hit; structures shrink it as they find closer hits.
    pub t_max: f32,
}

impl Ray {
    /// A ray over `0..=inf`.
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self::segment(origin, dir, 0.0, f32::INFINITY)
    }

    /// A ray over `t_min..=t_max`.
    #[inline]
    pub fn segment(origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self {
        let dir = Vec3A::from(dir);
        Ray { origin: origin.into(), dir, inv_dir: safe_inverse(dir), t_min, t_max }
    }

    /// A ray from its parts, `inv_dir` being what [`Ray::segment`] computes for `dir` (as a
    /// packet's rays are taken apart and put back together).
    #[inline(always)]
    pub(crate) fn from_parts(origin: Vec3A, dir: Vec3A, inv_dir: Vec3A, t_min: f32, t_max: f32) -> Self {
        debug_assert!(inv_dir.to_array().map(f32::to_bits) == safe_inverse(dir).to_array().map(f32::to_bits));
        Ray { origin, dir, inv_dir, t_min, t_max }
    }

    /// The origin.
    #[inline(always)]
    pub fn origin(&self) -> Vec3 {
        self.origin.into()
    }

    /// The direction, as given (not normalised).
    #[inline(always)]
    pub fn dir(&self) -> Vec3 {
        self.dir.into()
    }

    /// `1 / dir` per component, with `+inf` for zero components of either sign.
    #[inline(always)]
    pub fn inv_dir(&self) -> Vec3 {
        self.inv_dir.into()
    }

    /// The origin as an aligned vector, for code that reads the four lanes at once.
    #[inline(always)]
    pub(crate) fn origin_a(&self) -> Vec3A {
        self.origin
    }

    /// [`Ray::dir`] as an aligned vector.
    #[inline(always)]
    pub(crate) fn dir_a(&self) -> Vec3A {
        self.dir
    }

    /// [`Ray::inv_dir`] as an aligned vector.
    #[inline(always)]
    pub(crate) fn inv_dir_a(&self) -> Vec3A {
        self.inv_dir
    }

    /// The point at parameter `t`.
    #[inline(always)]
    pub fn at(&self, t: f32) -> Vec3 {
        (self.origin + self.dir * t).into()
    }

    /// The same ray over a different interval.
    #[inline(always)]
    pub fn with_range(&self, t_min: f32, t_max: f32) -> Self {
        Ray { t_min, t_max, ..*self }
    }

    /// A ray can hit something only if its origin and direction are finite, its direction is not
    /// zero and its interval holds a finite parameter (NaN bounds make it empty, and so do
    /// `inf..=inf` and `-inf..=-inf`). Structures answer "no hit" for any other ray without
    /// traversing anything.
    #[inline]
    pub fn is_valid(&self) -> bool {
        // Every query starts here, so the six coordinates are checked with vector comparisons.
        (self.origin.is_finite_mask() & self.dir.is_finite_mask()).all()
            && self.dir.cmpne(Vec3A::ZERO).any()
            && self.t_min <= self.t_max
            && self.t_min < f32::INFINITY
            && self.t_max > f32::NEG_INFINITY
    }
}

/// `1 / x` of each component, `+inf` for a zero of either sign (so that the slab test's NaN
/// handling only ever has to deal with one sign): one vector division, as every ray pays it.
#[inline(always)]
fn safe_inverse(x: Vec3A) -> Vec3A {
    Vec3A::select(x.cmpeq(Vec3A::ZERO), Vec3A::INFINITY, Vec3A::ONE / x)
}

/// [`safe_inverse`] of four lanes of a packet's row (the rays of a packet): the same operations, so
/// the same bits, lane by lane.
#[inline(always)]
pub(crate) fn safe_inverse_lanes(x: Vec4) -> Vec4 {
    Vec4::select(x.cmpeq(Vec4::ZERO), Vec4::INFINITY, Vec4::ONE / x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_of_zero_is_positive_infinity_for_both_signs() {
        let r = Ray::new(Vec3::ZERO, Vec3::new(0.0, -0.0, 2.0));
        assert_eq!(r.inv_dir().x, f32::INFINITY);
        assert_eq!(r.inv_dir().y, f32::INFINITY);
        assert_eq!(r.inv_dir().z, 0.5);
    }

    #[test]
    fn validity() {
        assert!(Ray::new(Vec3::ZERO, Vec3::X).is_valid());
        assert!(!Ray::new(Vec3::ZERO, Vec3::ZERO).is_valid());
        assert!(!Ray::new(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::X).is_valid());
        assert!(!Ray::new(Vec3::ZERO, Vec3::new(f32::INFINITY, 0.0, 0.0)).is_valid());
        assert!(!Ray::segment(Vec3::ZERO, Vec3::X, 0.0, f32::NAN).is_valid());
        assert!(!Ray::segment(Vec3::ZERO, Vec3::X, f32::NAN, 1.0).is_valid());
        assert!(!Ray::segment(Vec3::ZERO, Vec3::X, 2.0, 1.0).is_valid());
        assert!(Ray::segment(Vec3::ZERO, Vec3::X, 1.0, 1.0).is_valid());
        assert!(Ray::segment(Vec3::ZERO, Vec3::X, f32::NEG_INFINITY, f32::INFINITY).is_valid());
        assert!(!Ray::segment(Vec3::ZERO, Vec3::X, f32::INFINITY, f32::INFINITY).is_valid());
        assert!(!Ray::segment(Vec3::ZERO, Vec3::X, f32::NEG_INFINITY, f32::NEG_INFINITY).is_valid());
    }
}
