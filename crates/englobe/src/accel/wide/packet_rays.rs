//! A packet of up to [`PACKET`] rays prepared for the packet traversal ([`super::packet`]): each
//! ray's [`super::node::NodeRay`] as a structure of arrays, one [`Lanes`] row per coordinate, so
//! that the node tests of [`super::packet_kernels`] read each coordinate of all the rays with one
//! load (Wald, Slusallek, Benthin and Wagner 2001, "Interactive Rendering with Coherent Ray
//! Tracing"); the rays' checks and limits, made four rays at a time; and the packet's test
//! against the tree's box.

use glam::{BVec4A, Vec3A, Vec4};

use super::node::FAR_SCALE;
use super::packet_interval::PacketInterval;
use crate::geom::aabb::ROBUST_FAR_SCALE;
use crate::{Aabb, Ray};

/// Rays in one packet, at most.
pub const PACKET: usize = 16;

/// One float per ray of a packet, aligned for one AVX-512 load.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct Lanes(pub [f32; PACKET]);

/// A packet prepared for node tests: each ray's [`super::node::NodeRay`], as a structure of
/// arrays.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct PacketRays {
    /// Origins, one row per axis.
    pub origin: [Lanes; 3],
    /// Directions.
    pub dir: [Lanes; 3],
    /// Inverse directions.
    pub inv_dir: [Lanes; 3],
    /// Inverse directions times the robust far scale (see [`super::node::NodeRay::inv_far`]).
    pub inv_far: [Lanes; 3],
    /// The rays' `t_min`.
    pub t_min: Lanes,
    /// The rays' `t_max`.
    pub t_max: Lanes,
    /// Bit `i` set if ray `i` is valid ([`Ray::is_valid`]); the lanes beyond the rays are not.
    pub valid: u32,
    /// Bit `i` of `down[a]` is set if ray `i` goes down axis `a` (its near plane is the upper).
    pub down: [u32; 3],
    /// The bounds of the rays for culling a node's children all at once, when they allow it
    /// (see [`PacketInterval`]); `None` from [`PacketRays::new`], set by [`PacketRays::bound`].
    pub interval: Option<PacketInterval>,
}

/// The lanes whose interval `t_min..=t_max` holds a finite parameter (the interval test of
/// [`Ray::is_valid`]).
#[inline(always)]
pub(super) fn nonempty(t_min: Vec4, t_max: Vec4) -> BVec4A {
    t_min.cmple(t_max) & t_min.cmplt(Vec4::INFINITY) & t_max.cmpgt(Vec4::NEG_INFINITY)
}

/// The axes the rays in `lanes` (bit per lane) go down (bit per axis), if each axis is gone the
/// same way by all of them, as an interval asks ([`PacketInterval`]); `None` for no lane at all.
#[inline(always)]
pub(super) fn interval_axes(p: &PacketRays, lanes: u32) -> Option<u32> {
    if lanes == 0 {
        return None;
    }
    // One way along each axis: the lanes' signs all set or all clear.
    let mut down = 0;
    for (a, &d) in p.down.iter().enumerate() {
        match d & lanes {
            0 => {}
            d if d == lanes => down |= 1 << a,
            _ => return None,
        }
    }
    Some(down)
}

impl PacketRays {
    /// No ray: every row zero, no lane valid; what the makers of packets fill in.
    pub(super) const EMPTY: PacketRays = PacketRays {
        origin: [Lanes([0.0; PACKET]); 3],
        dir: [Lanes([0.0; PACKET]); 3],
        inv_dir: [Lanes([0.0; PACKET]); 3],
        inv_far: [Lanes([0.0; PACKET]); 3],
        t_min: Lanes([0.0; PACKET]),
        t_max: Lanes([0.0; PACKET]),
        valid: 0,
        down: [0; 3],
        interval: None,
    };

    /// Prepares up to [`PACKET`] rays; the lanes beyond `rays.len()` hold zeros, and no query may
    /// ask for them.
    #[inline(always)]
    pub fn new(rays: &[Ray]) -> Self {
        let mut p = PacketRays::EMPTY;
        p.fill(rays);
        p
    }

    /// [`PacketRays::new`] into a packet that is [`PacketRays::EMPTY`] (so that a caller which
    /// keeps the packet in place has it filled there rather than copied).
    #[inline(always)]
    pub(super) fn fill(&mut self, rays: &[Ray]) {
        debug_assert!(rays.len() <= PACKET);
        let p = self;
        // What `NodeRay::new` computes, four rays at a time: their vectors transposed into rows
        // of four lanes by shuffles, each row stored whole. (Storing each ray's coordinates one
        // by one and reading them back as rows made every read wait for the stores before it.)
        for (k, four) in rays.chunks(4).enumerate().take(PACKET / 4) {
            let ray = |j: usize| four.get(j);
            let rows = |v: fn(&Ray) -> glam::Vec3A| {
                let col = |j: usize| ray(j).map_or(Vec4::ZERO, |r| v(r).extend(0.0));
                glam::Mat4::from_cols(col(0), col(1), col(2), col(3)).transpose()
            };
            let (o, d, inv) = (rows(Ray::origin_a), rows(Ray::dir_a), rows(Ray::inv_dir_a));
            let lanes = 4 * k..4 * k + 4;
            for (a, (o, (d, inv))) in [
                (o.x_axis, (d.x_axis, inv.x_axis)),
                (o.y_axis, (d.y_axis, inv.y_axis)),
                (o.z_axis, (d.z_axis, inv.z_axis)),
            ]
            .into_iter()
            .enumerate()
            {
                o.write_to_slice(&mut p.origin[a].0[lanes.clone()]);
                d.write_to_slice(&mut p.dir[a].0[lanes.clone()]);
                inv.write_to_slice(&mut p.inv_dir[a].0[lanes.clone()]);
                (inv * FAR_SCALE).write_to_slice(&mut p.inv_far[a].0[lanes.clone()]);
                p.down[a] |= inv.cmplt(Vec4::ZERO).bitmask() << (4 * k);
            }
            let interval = |j: usize| ray(j).map_or(Vec4::ZERO, |r| Vec4::new(r.t_min, r.t_max, 0.0, 0.0));
            let t = glam::Mat4::from_cols(interval(0), interval(1), interval(2), interval(3)).transpose();
            let (t_min, t_max) = (t.x_axis, t.y_axis);
            t_min.write_to_slice(&mut p.t_min.0[lanes.clone()]);
            t_max.write_to_slice(&mut p.t_max.0[lanes]);
            // `Ray::is_valid` of the four, lane by lane (a missing ray's zero direction is not).
            let finite = o.x_axis.is_finite_mask()
                & o.y_axis.is_finite_mask()
                & o.z_axis.is_finite_mask()
                & d.x_axis.is_finite_mask()
                & d.y_axis.is_finite_mask()
                & d.z_axis.is_finite_mask();
            let moving = d.x_axis.cmpne(Vec4::ZERO) | d.y_axis.cmpne(Vec4::ZERO) | d.z_axis.cmpne(Vec4::ZERO);
            p.valid |= (finite & moving & nonempty(t_min, t_max)).bitmask() << (4 * k);
        }
    }

    /// How far each ray may enter a box ([`super::node::reach`] of its `t_max`), four lanes at a
    /// time with the same operations (so the same values, as a test checks); 0 in the lanes
    /// beyond the rays. (`reach` mapped over the lanes changed the inlining of the harness around
    /// its single-ray loops: 20 more instructions per ray inside the Sponza, by callgrind.)
    #[inline(always)]
    pub fn limits(&self) -> Lanes {
        let mut limits = Lanes([0.0; PACKET]);
        for (out, t_max) in limits.0.chunks_exact_mut(4).zip(self.t_max.0.chunks_exact(4)) {
            let t_max = Vec4::from_slice(t_max);
            (t_max + t_max.abs() * (ROBUST_FAR_SCALE - 1.0)).write_to_slice(out);
        }
        limits
    }

    /// Adds the interval of the rays in `lanes` (bit per lane: the ones a query traces), so that
    /// the SIMD kernels skip the children no such ray can enter: worth it once the packet has
    /// entered the tree's box.
    #[inline(always)]
    pub fn bound(&mut self, lanes: u32) {
        self.interval = self.interval(lanes);
    }

    /// The interval of the rays in `lanes` (bit per lane), as [`PacketInterval::new`] gives it
    /// for those rays, read from the rows four lanes at a time; `None` in the same cases, and for
    /// no lane at all.
    #[inline(always)]
    fn interval(&self, lanes: u32) -> Option<PacketInterval> {
        let down = interval_axes(self, lanes)?;
        let (mut o_lo, mut o_hi) = ([Vec4::INFINITY; 3], [Vec4::NEG_INFINITY; 3]);
        let (mut inv_lo, mut inv_hi) = ([Vec4::INFINITY; 3], [Vec4::NEG_INFINITY; 3]);
        let mut t_min = Vec4::INFINITY;
        for k in 0..PACKET / 4 {
            let m = lanes >> (4 * k) & 0xf;
            if m == 0 {
                continue;
            }
            let four = |l: &Lanes| Vec4::from_slice(&l.0[4 * k..4 * k + 4]);
            let taken = BVec4A::new(m & 1 != 0, m & 2 != 0, m & 4 != 0, m & 8 != 0);
            // The lanes left out take neutral values: infinities the extremes pass over.
            let (low, high) =
                (|v| Vec4::select(taken, v, Vec4::INFINITY), |v| Vec4::select(taken, v, Vec4::NEG_INFINITY));
            for a in 0..3 {
                let (o, inv) = (four(&self.origin[a]), four(&self.inv_dir[a]));
                let usable = o.is_finite_mask() & inv.is_finite_mask() & inv.cmpne(Vec4::ZERO);
                if usable.bitmask() & m != m {
                    return None;
                }
                (o_lo[a], o_hi[a]) = (o_lo[a].min(low(o)), o_hi[a].max(high(o)));
                (inv_lo[a], inv_hi[a]) = (inv_lo[a].min(low(inv)), inv_hi[a].max(high(inv)));
            }
            t_min = t_min.min(low(four(&self.t_min)));
        }
        let least = |v: [Vec4; 3]| Vec3A::from_array(v.map(Vec4::min_element));
        let greatest = |v: [Vec4; 3]| Vec3A::from_array(v.map(Vec4::max_element));
        Some(PacketInterval::from_bounds(
            down,
            [least(o_lo), greatest(o_hi)],
            [least(inv_lo), greatest(inv_hi)],
            t_min.min_element(),
        ))
    }

    /// Ray `i` of the packet, as it was given: the same origin, direction, inverse direction and
    /// interval, bit for bit.
    #[inline(always)]
    pub fn ray(&self, i: usize) -> Ray {
        let lane = |rows: &[Lanes; 3]| Vec3A::new(rows[0].0[i], rows[1].0[i], rows[2].0[i]);
        Ray::from_parts(lane(&self.origin), lane(&self.dir), lane(&self.inv_dir), self.t_min.0[i], self.t_max.0[i])
    }

    /// The lanes that may enter `bounds` within `t_min..=limits[i]`: [`super::node::may_enter`]
    /// lane by lane, the same products and comparisons, so the same answers, four lanes at a
    /// time (a packet's sixteen scalar tests cost more than its state). Lanes beyond the
    /// packet's rays answer anything: mask them.
    #[inline]
    pub fn may_enter(&self, bounds: &Aabb, limits: &Lanes) -> u32 {
        let mut mask = 0;
        for k in 0..PACKET / 4 {
            let four = |l: &Lanes| Vec4::from_slice(&l.0[4 * k..4 * k + 4]);
            let (mut enter, mut exit) = (four(&self.t_min), four(limits));
            for a in 0..3 {
                let (o, inv) = (four(&self.origin[a]), four(&self.inv_dir[a]));
                let (lo, hi) = (Vec4::splat(bounds.min[a]) - o, Vec4::splat(bounds.max[a]) - o);
                let down = inv.cmplt(Vec4::ZERO);
                let near = Vec4::select(down, hi, lo) * inv;
                let far = Vec4::select(down, lo, hi) * four(&self.inv_far[a]);
                // A NaN distance (an origin on the plane of a parallel ray) fails both
                // comparisons: it constrains nothing.
                enter = Vec4::select(near.cmpgt(enter), near, enter);
                exit = Vec4::select(far.cmplt(exit), far, exit);
            }
            mask |= enter.cmple(exit).bitmask() << (4 * k);
        }
        mask
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::*;
    use crate::accel::wide::node::{may_enter, reach};

    #[test]
    fn the_packet_box_test_answers_as_the_single_ray_one() {
        // Coordinates on the box's planes and zero direction components of both signs: NaN
        // distances, which constrain nothing in either test.
        let values = [-2.0f32, -1.0, -0.0, 0.0, 0.5, 1.0, 3.0];
        let dirs = [-1.0f32, -0.25, -0.0, 0.0, 0.5, 2.0];
        let mut rng = Pcg32::seed_from_u64(0x5eed_b0c5);
        let mut pick = |from: &[f32]| from[rng.random_range(0..from.len())];
        let (mut entered, mut refused) = (0, 0);
        for round in 0..2000 {
            let (a, b) = (
                Vec3::new(pick(&values), pick(&values), pick(&values)),
                Vec3::new(pick(&values), pick(&values), pick(&values)),
            );
            let bounds = Aabb::new(a.min(b), a.max(b));
            let rays: Vec<Ray> = (0..1 + round % PACKET)
                .map(|i| {
                    let origin = Vec3::new(pick(&values), pick(&values), pick(&values)) * 1.5;
                    // Half of them aimed at the box's centre, which often lies on its planes.
                    let aimed = bounds.center() - origin;
                    let dir = if i % 2 == 1 && aimed != Vec3::ZERO {
                        aimed
                    } else {
                        Vec3::new(pick(&dirs), pick(&dirs), pick(&dirs))
                    };
                    let (t_min, t_max) = [(0.0, f32::INFINITY), (0.5, 1.0), (0.0, 2.5), (3.0, 3.0)][i % 4];
                    Ray::segment(origin, dir, t_min, t_max)
                })
                .filter(Ray::is_valid)
                .collect();
            let packet = PacketRays::new(&rays);
            let limits = Lanes(std::array::from_fn(|i| rays.get(i).map_or(0.0, |r| reach(r.t_max))));
            let mask = packet.may_enter(&bounds, &limits);
            for (i, ray) in rays.iter().enumerate() {
                let expected = may_enter(&bounds, ray, limits.0[i]);
                assert_eq!(mask >> i & 1 != 0, expected, "{ray:?} and {bounds:?}");
                entered += expected as u32;
                refused += !expected as u32;
            }
        }
        assert!(entered > 1000 && refused > 1000, "{entered} entered, {refused} refused");
    }

    #[test]
    fn a_packet_checks_and_limits_its_rays_as_each_ray_does() {
        let mut rng = Pcg32::seed_from_u64(0x7a11_d0e5);
        let values = [0.0f32, -0.0, 1.5, -2.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, 1e30];
        let mut pick = |from: &[f32]| from[rng.random_range(0..from.len())];
        let (mut valid, mut invalid) = (0, 0);
        for round in 0..3_000 {
            let rays: Vec<Ray> = (0..1 + round % PACKET)
                .map(|_| {
                    // Mostly ordinary rays, each coordinate sometimes replaced by an edge case.
                    let mut v = |x: f32| if pick(&[0.0, 0.0, 0.0, 1.0]) == 1.0 { pick(&values) } else { x };
                    let o = Vec3::new(v(0.5), v(-1.0), v(2.0));
                    let d = Vec3::new(v(0.3), v(1.0), v(-0.7));
                    Ray::segment(o, d, v(0.0), v(10.0))
                })
                .collect();
            let packet = PacketRays::new(&rays);
            let limits = packet.limits();
            for (i, ray) in rays.iter().enumerate() {
                assert_eq!(packet.valid >> i & 1 != 0, ray.is_valid(), "{ray:?}");
                assert_eq!(limits.0[i].to_bits(), reach(ray.t_max).to_bits(), "{ray:?}");
                assert_eq!(packet.t_max.0[i].to_bits(), ray.t_max.to_bits());
                valid += ray.is_valid() as u32;
                invalid += !ray.is_valid() as u32;
            }
            assert_eq!(packet.valid >> rays.len(), 0, "lanes beyond the rays are not valid");
        }
        assert!(valid > 5_000 && invalid > 5_000, "{valid} valid, {invalid} invalid");
    }

    #[test]
    fn the_interval_of_some_lanes_is_the_interval_of_their_rays() {
        let mut rng = Pcg32::seed_from_u64(0x1a7e_b0da);
        let mut some = 0;
        for round in 0..3_000 {
            let signs = Vec3::new(1.0, -1.0, 1.0) * if round % 5 == 0 { -1.0 } else { 1.0 };
            let rays: Vec<Ray> = (0..1 + round % PACKET)
                .map(|_| {
                    let o = Vec3::new(rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0), 0.0);
                    // Now and then a ray going the other way along x, or along no axis at all.
                    let mut d = Vec3::new(rng.random_range(0.1..1.0), rng.random_range(0.1..1.0), 0.5) * signs;
                    match rng.random_range(0..40) {
                        0 => d.x = -d.x,
                        1 => d.y = 0.0,
                        _ => {}
                    }
                    Ray::segment(o, d, rng.random_range(-1.0..1.0), 10.0)
                })
                .collect();
            let lanes = rng.random_range(0..1u32 << rays.len());
            let chosen: Vec<Ray> = (0..rays.len()).filter(|&i| lanes >> i & 1 != 0).map(|i| rays[i]).collect();
            let expected = PacketInterval::new(&chosen);
            assert_eq!(PacketRays::new(&rays).interval(lanes), expected, "lanes {lanes:b} of {rays:?}");
            some += expected.is_some() as u32;
        }
        assert!(some > 1_000, "{some}");
    }
}
