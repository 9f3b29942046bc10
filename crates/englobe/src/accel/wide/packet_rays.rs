//! A packet of up to [`PACKET`] rays prepared for the packet traversal ([`super::packet`]): each
//! ray's [`super::node::NodeRay`] as a structure of arrays, one [`Lanes`] row per coordinate, so
//! that the node tests of [`super::packet_kernels`] read each coordinate of all the rays with one
//! load (Wald, Slusallek, Benthin and Wagner 2001, "Interactive Rendering with Coherent Ray
//! Tracing"); the rays' checks and limits, made four rays at a time; and the packet's test
//! against the tree's box.

use glam::Vec4;

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

impl PacketRays {
    /// Prepares up to [`PACKET`] rays; the lanes beyond `rays.len()` hold zeros, and no query may
    /// ask for them.
    #[inline(always)]
    pub fn new(rays: &[Ray]) -> Self {
        debug_assert!(rays.len() <= PACKET);
        let zero = Lanes([0.0; PACKET]);
        let mut p = PacketRays {
            origin: [zero; 3],
            inv_dir: [zero; 3],
            inv_far: [zero; 3],
            t_min: zero,
            t_max: zero,
            valid: 0,
            down: [0; 3],
            interval: None,
        };
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
            for (a, (o, inv)) in
                [(o.x_axis, inv.x_axis), (o.y_axis, inv.y_axis), (o.z_axis, inv.z_axis)].into_iter().enumerate()
            {
                o.write_to_slice(&mut p.origin[a].0[lanes.clone()]);
                inv.write_to_slice(&mut p.inv_dir[a].0[lanes.clone()]);
                (inv * ROBUST_FAR_SCALE).write_to_slice(&mut p.inv_far[a].0[lanes.clone()]);
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
            let nonempty = t_min.cmple(t_max) & t_min.cmplt(Vec4::INFINITY) & t_max.cmpgt(Vec4::NEG_INFINITY);
            p.valid |= (finite & moving & nonempty).bitmask() << (4 * k);
        }
        p
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

    /// Adds the interval of `rays` (the ones this packet was made from), so that the SIMD kernels
    /// skip the children no ray can enter: worth it once the packet has entered the tree's box.
    #[inline(always)]
    pub fn bound(&mut self, rays: &[Ray]) {
        self.interval = PacketInterval::new(rays);
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
}
