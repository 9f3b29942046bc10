//! Primary rays in packets: a tile's pixels taken four by four, the sixteen camera rays of each
//! sample traced together ([`englobe::World::closest_hit_packet`]: one node test for the whole
//! packet, see `englobe::accel::wide::packet`), then each pixel's sample finished by the
//! integrator from its hit, as if it had found the hit itself. Whitted's integrator also traces
//! the packet's shadow rays toward each light together ([`crate::whitted::Whitted::radiance_packet`]).
//!
//! Every pixel keeps its own random numbers, drawn in the same order, and every ray its own
//! closest hit, so the image is bit for bit the one a pixel-by-pixel render makes. What changes is
//! the work counts (a packet visits the union of its rays' nodes), so renders that count their
//! work, record a cost image, sample adaptively or skip pixels go pixel by pixel; so do worlds
//! that packets would not walk together ([`englobe::World::walks_packets`]: the teaching
//! structures), which have nothing to gain.

use englobe::{Counters, Ray, Vec3, WorldHit};

use crate::camera::ImageCamera;
use crate::render::{Integrator, Renderer};
use crate::sampler::PixelSampler;
use crate::stats::{RayKind, Tally};

/// Side of a packet's square of pixels.
const BLOCK: u32 = 4;
/// Pixels (rays) per packet: as many as Whitted's integrator shades at once.
const PACKET: usize = crate::whitted::PACKET;
const _: () = assert!((BLOCK * BLOCK) as usize == PACKET, "a packet is a square of pixels");

impl Renderer<'_> {
    /// Whether this render traces its primary rays in packets (see the module documentation):
    /// only worlds on the fast path have something to gain.
    pub(crate) fn primary_packets(&self) -> bool {
        !self.count_work
            && !self.record_cost
            && self.supersampling.is_none()
            && self.stride == 1
            && self.world.walks_packets()
    }

    /// The pixels of the tile `(x0, y0)..(x1, y1)`, row by row, primary rays traced in packets;
    /// `None` if `cancelled` says so between two packets. Not inlined, so that profiles (and
    /// `scripts/render-instructions.sh`) find it by name.
    #[inline(never)]
    pub(crate) fn tile_in_packets<C: Counters>(
        &self,
        camera: &ImageCamera,
        integrator: &Integrator,
        (x0, y0, x1, y1): (u32, u32, u32, u32),
        tally: &mut Tally<C>,
        cancelled: &impl Fn() -> bool,
    ) -> Option<Vec<Vec3>> {
        let width = (x1 - x0) as usize;
        let mut pixels = vec![Vec3::ZERO; width * (y1 - y0) as usize];
        let mut rays = [Ray::new(Vec3::ZERO, Vec3::Z); PACKET];
        let mut hits = [None; PACKET];
        for by in (y0..y1).step_by(BLOCK as usize) {
            for bx in (x0..x1).step_by(BLOCK as usize) {
                if cancelled() {
                    return None;
                }
                // The block's pixels (fewer at the tile's right and bottom edges), row by row.
                let mut at = [(0u32, 0u32); PACKET];
                let mut n = 0;
                for y in by..(by + BLOCK).min(y1) {
                    for x in bx..(bx + BLOCK).min(x1) {
                        at[n] = (x, y);
                        n += 1;
                    }
                }
                let mut rngs: [PixelSampler; PACKET] =
                    std::array::from_fn(|i| self.pixel_sampler(at[i.min(n - 1)].0, at[i.min(n - 1)].1));
                let mut sums = [Vec3::ZERO; PACKET];
                for _ in 0..self.samples {
                    for i in 0..n {
                        let rng = &mut rngs[i];
                        rng.start_sample();
                        let (dx, dy) = self.sample_offset(rng);
                        rays[i] = self.camera_ray(camera, at[i].0, at[i].1, dx, dy, rng);
                    }
                    let vis = integrator.visibility();
                    vis.closest_hit_packet(&rays[..n], &mut hits[..n], &mut tally.work[RayKind::Primary as usize]);
                    let mut radiances = [Vec3::ZERO; PACKET];
                    integrator.radiances_from(&rays[..n], &hits[..n], &mut rngs[..n], tally, &mut radiances[..n]);
                    for i in 0..n {
                        let radiance = self.clamped(radiances[i]);
                        // One sample is the pixel itself (not `0 + sample`, which would turn -0 into +0).
                        sums[i] = if self.samples == 1 { radiance } else { sums[i] + radiance };
                    }
                }
                for (i, &(x, y)) in at[..n].iter().enumerate() {
                    let value = if self.samples == 1 { sums[i] } else { sums[i] / self.samples as f32 };
                    pixels[(y - y0) as usize * width + (x - x0) as usize] = value;
                }
            }
        }
        Some(pixels)
    }
}

impl Integrator<'_> {
    /// What decides visibility for the integrator's rays.
    fn visibility(&self) -> &crate::visibility::Visibility<'_> {
        match self {
            Integrator::Whitted(w) => w.visibility(),
            Integrator::Path(p) => p.visibility(),
        }
    }

    /// The radiance of each primary ray, `out[i]` for `rays[i]` whose closest hit is `hits[i]`:
    /// Whitted's shadow rays toward each light in packets too, the path tracer's samples one by
    /// one (each draws its own random numbers).
    fn radiances_from<C: Counters>(
        &self,
        rays: &[Ray],
        hits: &[Option<WorldHit>],
        rngs: &mut [PixelSampler],
        tally: &mut Tally<C>,
        out: &mut [Vec3],
    ) {
        match self {
            Integrator::Whitted(w) => w.radiance_packet(rays, hits, tally, out),
            Integrator::Path(p) => {
                for (i, o) in out.iter_mut().enumerate() {
                    *o = p.radiance_from(&rays[i], Some(hits[i]), &mut rngs[i], tally);
                }
            }
        }
    }
}
