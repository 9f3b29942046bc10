//! One test of a node's eight children for a whole packet: interval arithmetic over the packet's
//! rays, which finds the children that no ray of the packet can enter before any ray is tested
//! against them. This is the interval culling of entire packets of Wald, Boulos and Shirley
//! (2007), "Ray Tracing Deformable Scenes Using Dynamic Bounding Volume Hierarchies" (ACM TOG
//! 26(1)), and of Boulos, Wald, Shirley and others (2006), "Geometric and Arithmetic Culling
//! Methods for Entire Ray Packets" (University of Utah, UUCS-06-010), on eight boxes at once.
//!
//! Each ray's slab test ([`super::node::child_entry_scalar`]) computes per axis
//! `t_near = (near - o) * inv` and `t_far = (far - o) * inv_far`, rounded (it writes them
//! `(o - near) * -inv`, the same numbers but for the sign of a zero). When the packet's rays
//! all go the same way along every axis (a camera's tile), each axis's near and far planes are the
//! same rows for all of them, and since rounding is monotonic each ray's distances lie within what
//! the extreme origins and inverse directions give:
//!
//! - `near - o` is smallest at the largest origin and largest at the smallest one, rounded or not;
//! - a product `x * inv`, for `inv` between `inv_lo` and `inv_hi`, lies between `x * inv_lo` and
//!   `x * inv_hi` (it is linear in `inv`), and the rounded one between their rounded values;
//! - a ray going up an axis (`inv > 0`) has its least `t_near` at its least `near - o`, a ray going
//!   down (`inv < 0`) at its greatest, and the other way round for `t_far`.
//!
//! So every ray enters a box no earlier than the greatest of the lower bounds of its three
//! `t_near` and of `t_min`, and leaves it no later than the least of the upper bounds of its three
//! `t_far`: where the first exceeds the second, no ray of the packet enters the box, and the box
//! needs no ray test.
//! A box some ray may enter is tested ray by ray as before, so every ray keeps its own answer.
//! Only packets whose origins and inverse directions are all finite, with no zero inverse, get an
//! interval: then no distance is NaN and the argument holds for the empty slots' infinite planes
//! too (they are never candidates).

use glam::Vec3A;

use super::node::{FAR_SCALE, ROWS, WIDTH, WideNode};
use crate::Ray;

/// The bounds of a packet's rays for the interval test of a node's children.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PacketInterval {
    /// Row of each axis's near planes in [`WideNode::bounds`] (`2 * axis`, plus 1 if the rays go
    /// down the axis); the far planes are the axis's other row. Below [`ROWS`].
    near_row: [usize; 3],
    /// Per axis, the origin coordinate that makes `near - o` least towards the boxes (the largest
    /// going up, the smallest going down).
    near_origin: [f32; 3],
    /// Per axis, the origin coordinate that makes `far - o` greatest towards the boxes.
    far_origin: [f32; 3],
    /// Per axis, the least and the greatest inverse direction.
    inv: [[f32; 2]; 3],
    /// Per axis, the least and the greatest far factor (`inv * FAR_SCALE`, as each ray
    /// rounds it: rounding keeps the order).
    inv_far: [[f32; 2]; 3],
    /// The least `t_min` of the rays.
    t_min: f32,
}

impl PacketInterval {
    /// The interval of `rays` (at least one), or `None` if they do not all go the same way along
    /// every axis, or if an origin or an inverse direction is not finite or an inverse is zero.
    /// Rays left out of a query may be in `rays`: a wider interval culls less, never wrongly.
    #[inline(always)]
    pub fn new(rays: &[Ray]) -> Option<Self> {
        let first = rays.first()?;
        let down = first.inv_dir().cmplt(glam::Vec3::ZERO).bitmask();
        let (mut o_lo, mut o_hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        let (mut inv_lo, mut inv_hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        let mut t_min = f32::INFINITY;
        for ray in rays {
            let (o, inv) = (Vec3A::from(ray.origin()), Vec3A::from(ray.inv_dir()));
            let usable = (o.is_finite_mask() & inv.is_finite_mask() & inv.cmpne(Vec3A::ZERO)).all();
            if !usable || inv.cmplt(Vec3A::ZERO).bitmask() != down {
                return None;
            }
            (o_lo, o_hi) = (o_lo.min(o), o_hi.max(o));
            (inv_lo, inv_hi) = (inv_lo.min(inv), inv_hi.max(inv));
            // A NaN `t_min` (a ray no query asks for) is passed over by `min`.
            t_min = t_min.min(ray.t_min);
        }
        Some(Self::from_bounds(down, [o_lo, o_hi], [inv_lo, inv_hi], t_min))
    }

    /// The interval of rays whose origins lie within `origin` (least and greatest per axis),
    /// inverse directions within `inv`, going down the axes of `down` (bit per axis).
    #[inline(always)]
    pub(super) fn from_bounds(down: u32, origin: [Vec3A; 2], inv: [Vec3A; 2], t_min: f32) -> Self {
        let ([o_lo, o_hi], [inv_lo, inv_hi]) = (origin, inv);
        let going_down = |a: usize| down >> a & 1 != 0;
        let (inv_far_lo, inv_far_hi) = (inv_lo * FAR_SCALE, inv_hi * FAR_SCALE);
        // The arrays spelled out: `[0, 1, 2].map` compiled to calls.
        let down_or_up = |a: usize, down: Vec3A, up: Vec3A| if going_down(a) { down[a] } else { up[a] };
        PacketInterval {
            near_row: [going_down(0) as usize, 2 + going_down(1) as usize, 4 + going_down(2) as usize],
            near_origin: [down_or_up(0, o_lo, o_hi), down_or_up(1, o_lo, o_hi), down_or_up(2, o_lo, o_hi)],
            far_origin: [down_or_up(0, o_hi, o_lo), down_or_up(1, o_hi, o_lo), down_or_up(2, o_hi, o_lo)],
            inv: [[inv_lo.x, inv_hi.x], [inv_lo.y, inv_hi.y], [inv_lo.z, inv_hi.z]],
            inv_far: [[inv_far_lo.x, inv_far_hi.x], [inv_far_lo.y, inv_far_hi.y], [inv_far_lo.z, inv_far_hi.z]],
            t_min,
        }
    }

    /// The children of `node` that some ray of the packet may enter (bit per slot), one plane at
    /// a time: the reference the SIMD form is tested against.
    pub fn candidates_scalar(&self, node: &WideNode) -> u32 {
        let mut mask = 0;
        for slot in 0..WIDTH {
            let (mut enter, mut exit) = (self.t_min, f32::INFINITY);
            for a in 0..3 {
                let x = node.bounds[self.near_row[a]][slot] - self.near_origin[a];
                let xf = node.bounds[self.near_row[a] ^ 1][slot] - self.far_origin[a];
                enter = enter.max((x * self.inv[a][0]).min(x * self.inv[a][1]));
                exit = exit.min((xf * self.inv_far[a][0]).max(xf * self.inv_far[a][1]));
            }
            mask |= ((enter <= exit) as u32) << slot;
        }
        mask
    }

    /// [`PacketInterval::candidates_scalar`] on the eight slots at once, with AVX.
    ///
    /// # Safety
    /// The caller is compiled with AVX and runs on a processor that has it.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub unsafe fn candidates_avx(&self, node: &WideNode, enter_at: &mut [f32; WIDTH]) -> u32 {
        use std::arch::x86_64::*;
        const { assert!(ROWS == 6 && WIDTH == 8) };
        // SAFETY: AVX is the caller's guarantee; `near_row` is below `ROWS` (made so by `new`),
        // and so is its partner `near_row ^ 1`; each row is 32 bytes of a node aligned to 64.
        unsafe {
            let mut enter = _mm256_set1_ps(self.t_min);
            let mut exit = _mm256_set1_ps(f32::INFINITY);
            for a in 0..3 {
                let near = _mm256_load_ps(node.bounds.get_unchecked(self.near_row[a]).as_ptr());
                let far = _mm256_load_ps(node.bounds.get_unchecked(self.near_row[a] ^ 1).as_ptr());
                let x = _mm256_sub_ps(near, _mm256_set1_ps(self.near_origin[a]));
                let xf = _mm256_sub_ps(far, _mm256_set1_ps(self.far_origin[a]));
                let lower = _mm256_min_ps(
                    _mm256_mul_ps(x, _mm256_set1_ps(self.inv[a][0])),
                    _mm256_mul_ps(x, _mm256_set1_ps(self.inv[a][1])),
                );
                let upper = _mm256_max_ps(
                    _mm256_mul_ps(xf, _mm256_set1_ps(self.inv_far[a][0])),
                    _mm256_mul_ps(xf, _mm256_set1_ps(self.inv_far[a][1])),
                );
                enter = _mm256_max_ps(lower, enter);
                exit = _mm256_min_ps(upper, exit);
            }
            _mm256_storeu_ps(enter_at.as_mut_ptr(), enter);
            _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(enter, exit)) as u32
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::*;
    use crate::Aabb;
    use crate::accel::wide::node::{NodeRay, child_entry_scalar, reach};

    #[test]
    fn no_child_a_ray_enters_is_ever_culled() {
        // Boxes on a coarse grid and packets of nearby rays going the same way, some of them
        // from origins on the boxes' planes, so that the bounds are often tight.
        let mut rng = Pcg32::seed_from_u64(0x1a7e_57a1);
        let (mut culled, mut kept, mut entered) = (0u32, 0u32, 0u32);
        for round in 0..4_000 {
            let mut node = WideNode::EMPTY_NODE;
            for slot in 0..1 + round % WIDTH {
                let p =
                    |rng: &mut Pcg32| Vec3::new(rng.random_range(-4..4) as f32, rng.random_range(-4..4) as f32, 0.0);
                let (a, b) = (p(&mut rng), p(&mut rng) + Vec3::new(0.0, 0.0, rng.random_range(0..3) as f32));
                node.set_child(slot, &Aabb::new(a.min(b), a.max(b)), slot as u32, 0);
            }
            let signs = Vec3::new(
                if rng.random::<bool>() { 1.0 } else { -1.0 },
                if rng.random::<bool>() { 1.0 } else { -1.0 },
                if rng.random::<bool>() { 1.0 } else { -1.0 },
            );
            let centre =
                Vec3::new(rng.random_range(-6.0..6.0), rng.random_range(-6.0..6.0), rng.random_range(-3.0..3.0));
            let spread = [0.0, 0.01, 1.0][round % 3];
            let rays: Vec<Ray> = (0..1 + round % 16)
                .map(|_| {
                    let jitter = Vec3::new(rng.random(), rng.random(), rng.random()) * spread;
                    let dir = Vec3::new(
                        rng.random_range(0.05..1.0),
                        rng.random_range(0.05..1.0),
                        rng.random_range(0.05..1.0),
                    );
                    let t_max = [f32::INFINITY, 2.0][rng.random_range(0..2)];
                    Ray::segment((centre + jitter).round() + jitter * (round % 2) as f32, dir * signs, 0.0, t_max)
                })
                .collect();
            let interval = PacketInterval::new(&rays).expect("finite rays going one way");
            let candidates = interval.candidates_scalar(&node);
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx") {
                // SAFETY: the processor has AVX (the function is not inlined into this one).
                assert_eq!(unsafe { interval.candidates_avx(&node, &mut [0.0; WIDTH]) }, candidates);
            }
            for slot in 0..WIDTH {
                let any_enters =
                    rays.iter().any(|r| child_entry_scalar(&node, slot, &NodeRay::new(r), reach(r.t_max)).is_some());
                let candidate = candidates >> slot & 1 != 0;
                assert!(candidate || !any_enters, "slot {slot} of {node:?} culled for {rays:?}");
                culled += !candidate as u32;
                kept += candidate as u32;
                entered += any_enters as u32;
            }
        }
        // Both outcomes, and a cull that is not only of the empty slots.
        assert!(culled > 10_000 && kept > 3_000 && entered > 1_500, "{culled} culled, {kept} kept, {entered} entered");
    }

    #[test]
    fn packets_going_several_ways_or_with_zero_inverses_get_no_interval() {
        let up = Ray::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 1.0));
        let down_x = Ray::new(Vec3::ZERO, Vec3::new(-1.0, 1.0, 1.0));
        let flat = Ray::new(Vec3::ZERO, Vec3::new(1.0, 0.0, 1.0));
        assert!(PacketInterval::new(&[up, up]).is_some());
        assert_eq!(PacketInterval::new(&[up, down_x]), None);
        assert_eq!(PacketInterval::new(&[up, flat]), None);
        assert_eq!(PacketInterval::new(&[Ray::new(Vec3::new(f32::INFINITY, 0.0, 0.0), Vec3::ONE)]), None);
        assert_eq!(PacketInterval::new(&[]), None);
    }
}
