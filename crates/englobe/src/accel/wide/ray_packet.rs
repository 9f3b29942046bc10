//! Up to sixteen rays handed over as a structure of arrays, and their hits given back the same
//! way: the packet interface of [`super::TriangleBvh`] for programs that make their rays in
//! packets (a camera's 4 x 4 pixels, shadow rays of neighbouring points), laid out as Embree's
//! `RTCRay16` and `RTCHit16` are (Wald et al. 2014, "Embree: A Kernel Framework for Efficient
//! CPU Ray Tracing"). The rays go straight into the packet traversal's rows: no ray is built,
//! checked or transposed one at a time, which is most of what a packet of [`Ray`]s costs before
//! its first node.

use glam::{Vec3, Vec4};

use super::node::FAR_SCALE;
use super::packet_rays::{Lanes, PACKET, PacketRays, nonempty};
use crate::Ray;
use crate::accel::Hit;
use crate::geom::ray::safe_inverse_lanes;

/// Up to sixteen rays, one row per coordinate: lane `i` of every row is ray `i`. The queries
/// take a mask of the lanes to trace; the others are never read. A lane whose ray is not valid
/// ([`Ray::is_valid`]: a non-finite origin or direction, a zero direction, an empty interval)
/// gets no hit, as that ray would alone.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct RayPacket {
    /// The origins' coordinates, one row per axis.
    pub origin: [[f32; PACKET]; 3],
    /// The directions' coordinates (not normalised: `t` is measured in units of their length).
    pub dir: [[f32; PACKET]; 3],
    /// The smallest parameter that counts as a hit, per ray.
    pub t_min: [f32; PACKET],
    /// The largest parameter that counts as a hit, per ray.
    pub t_max: [f32; PACKET],
}

impl Default for RayPacket {
    /// Sixteen zero rays (none valid).
    fn default() -> Self {
        RayPacket { origin: [[0.0; PACKET]; 3], dir: [[0.0; PACKET]; 3], t_min: [0.0; PACKET], t_max: [0.0; PACKET] }
    }
}

impl RayPacket {
    /// Rays in a packet.
    pub const LANES: usize = PACKET;

    /// Sets lane `lane` to the ray `origin + t * dir`, `t` in `t_min..=t_max`.
    ///
    /// # Panics
    /// If `lane` is not below [`RayPacket::LANES`].
    #[inline(always)]
    pub fn set(&mut self, lane: usize, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) {
        for a in 0..3 {
            self.origin[a][lane] = origin[a];
            self.dir[a][lane] = dir[a];
        }
        (self.t_min[lane], self.t_max[lane]) = (t_min, t_max);
    }

    /// The ray of lane `lane`.
    ///
    /// # Panics
    /// If `lane` is not below [`RayPacket::LANES`].
    pub fn ray(&self, lane: usize) -> Ray {
        let row = |rows: &[[f32; PACKET]; 3]| Vec3::new(rows[0][lane], rows[1][lane], rows[2][lane]);
        Ray::segment(row(&self.origin), row(&self.dir), self.t_min[lane], self.t_max[lane])
    }

    /// The packet prepared for the traversal, its rays valid only in `active`, written into `p`
    /// (every field of it; in place, see `triangle_packet`'s `PacketSource`): what
    /// [`PacketRays::new`] makes of the same rays, computed row by row, four lanes at a time.
    #[inline(always)]
    pub(super) fn prepare_into(&self, active: u32, p: &mut PacketRays) {
        (p.t_min, p.t_max, p.valid, p.down, p.interval) = (Lanes(self.t_min), Lanes(self.t_max), 0, [0; 3], None);
        for k in 0..PACKET / 4 {
            let lanes = 4 * k..4 * k + 4;
            let four = |row: &[f32; PACKET]| Vec4::from_slice(&row[lanes.clone()]);
            let (mut finite, mut moving) = (glam::BVec4A::splat(true), glam::BVec4A::splat(false));
            for a in 0..3 {
                let (o, d) = (four(&self.origin[a]), four(&self.dir[a]));
                // `Ray::segment`'s inverse, four lanes at a time (a test checks the bits).
                let inv = safe_inverse_lanes(d);
                o.write_to_slice(&mut p.origin[a].0[lanes.clone()]);
                d.write_to_slice(&mut p.dir[a].0[lanes.clone()]);
                inv.write_to_slice(&mut p.inv_dir[a].0[lanes.clone()]);
                (inv * FAR_SCALE).write_to_slice(&mut p.inv_far[a].0[lanes.clone()]);
                p.down[a] |= inv.cmplt(Vec4::ZERO).bitmask() << (4 * k);
                finite &= o.is_finite_mask() & d.is_finite_mask();
                moving |= d.cmpne(Vec4::ZERO);
            }
            let (t_min, t_max) = (four(&self.t_min), four(&self.t_max));
            p.valid |= (finite & moving & nonempty(t_min, t_max)).bitmask() << (4 * k);
        }
        p.valid &= active;
    }
}

/// The closest hits of a packet's rays, one row per field: lane `i` is ray `i`'s hit, if
/// `prim[i]` is not [`PacketHits::MISS`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct PacketHits {
    /// Hit distances (a lane without a hit holds its ray's `t_max`).
    pub t: [f32; PACKET],
    /// First barycentric coordinate (the weight of the triangle's second vertex).
    pub u: [f32; PACKET],
    /// Second barycentric coordinate (the weight of its third vertex).
    pub v: [f32; PACKET],
    /// The triangle hit, or [`PacketHits::MISS`].
    pub prim: [u32; PACKET],
}

impl PacketHits {
    /// The `prim` of a lane without a hit.
    pub const MISS: u32 = u32::MAX;

    /// Lanes that hit something, bit per lane.
    #[inline]
    pub fn mask(&self) -> u32 {
        self.prim.iter().enumerate().fold(0, |m, (i, &p)| m | ((p != Self::MISS) as u32) << i)
    }

    /// The hit of lane `lane`.
    ///
    /// # Panics
    /// If `lane` is not below [`RayPacket::LANES`].
    #[inline]
    pub fn hit(&self, lane: usize) -> Option<Hit> {
        let prim = self.prim[lane];
        (prim != Self::MISS).then(|| Hit { t: self.t[lane], prim, u: self.u[lane], v: self.v[lane] })
    }
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::*;

    #[test]
    fn a_packet_of_rows_prepares_as_a_packet_of_rays() {
        // Ordinary rays, and coordinates replaced by zeros of both signs, infinities and NaN.
        let mut rng = Pcg32::seed_from_u64(0x50a_1a4e5);
        let values = [0.0f32, -0.0, 1.5, -2.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, 1e-40];
        let mut pick = |from: &[f32]| from[rng.random_range(0..from.len())];
        let (mut valid, mut invalid) = (0, 0);
        for round in 0..2_000 {
            let mut packet = RayPacket::default();
            let mut rays = Vec::new();
            let len = 1 + round % PACKET;
            for lane in 0..len {
                let mut v = |x: f32| if pick(&[0.0, 0.0, 0.0, 1.0]) == 1.0 { pick(&values) } else { x };
                let (o, d) = (Vec3::new(v(0.5), v(-1.0), v(2.0)), Vec3::new(v(0.3), v(1.0), v(-0.7)));
                let (t_min, t_max) = (v(0.0), v(10.0));
                packet.set(lane, o, d, t_min, t_max);
                rays.push(Ray::segment(o, d, t_min, t_max));
            }
            let active = (1u32 << len) - 1;
            // Into a packet that holds other rays, an interval included: every field is written.
            let prepare = |active: u32| {
                let mut p = PacketRays::new(&[Ray::new(Vec3::splat(3.0), Vec3::new(-1.0, -2.0, -0.5)); PACKET]);
                p.bound(u32::MAX >> (32 - PACKET));
                assert!(p.interval.is_some());
                packet.prepare_into(active, &mut p);
                p
            };
            let (from_rows, from_rays) = (prepare(active), PacketRays::new(&rays));
            let bits = |l: &Lanes| l.0[..len].iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            for a in 0..3 {
                assert_eq!(bits(&from_rows.origin[a]), bits(&from_rays.origin[a]));
                assert_eq!(bits(&from_rows.dir[a]), bits(&from_rays.dir[a]));
                assert_eq!(bits(&from_rows.inv_dir[a]), bits(&from_rays.inv_dir[a]), "{rays:?}");
                assert_eq!(bits(&from_rows.inv_far[a]), bits(&from_rays.inv_far[a]));
                assert_eq!(from_rows.down[a] & active, from_rays.down[a] & active);
            }
            assert_eq!(bits(&from_rows.t_min), bits(&from_rays.t_min));
            assert_eq!(bits(&from_rows.t_max), bits(&from_rays.t_max));
            assert_eq!(from_rows.valid, from_rays.valid);
            assert_eq!(from_rows.interval, None);
            for (i, ray) in rays.iter().enumerate() {
                assert_eq!(format!("{:?}", from_rows.ray(i)), format!("{ray:?}"), "lane {i}");
                assert_eq!(format!("{:?}", packet.ray(i)), format!("{ray:?}"), "lane {i}");
                valid += ray.is_valid() as u32;
                invalid += !ray.is_valid() as u32;
            }
            // Lanes outside the mask are never valid.
            assert_eq!(prepare(active & 0x5555).valid, from_rays.valid & 0x5555);
        }
        assert!(valid > 3_000 && invalid > 3_000, "{valid} valid, {invalid} invalid");
    }

    #[test]
    fn hits_read_back_lane_by_lane() {
        let mut hits =
            PacketHits { t: [1.0; PACKET], u: [0.25; PACKET], v: [0.5; PACKET], prim: [PacketHits::MISS; PACKET] };
        hits.prim[3] = 7;
        assert_eq!(hits.mask(), 1 << 3);
        assert_eq!(hits.hit(3), Some(Hit { t: 1.0, prim: 7, u: 0.25, v: 0.5 }));
        assert_eq!(hits.hit(2), None);
    }
}
