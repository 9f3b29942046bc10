//! Batches of a [`World`]'s two queries over slices of rays: the single-ray queries, ray after
//! ray, split across threads for large batches ([`crate::accel::interface::batch`]); no
//! allocation per ray, the same answers as one ray at a time.

use super::{World, WorldHit};
use crate::Ray;
use crate::accel::interface::batch::run_batch;
use crate::accel::{BatchSizeMismatch, NoCount};

impl World {
    /// The closest hit of every ray, `hits[i]` for `rays[i]` ([`World::closest_hit`]). The two
    /// slices must be as long.
    ///
    /// ```
    /// use englobe::{AccelKind, Ray, Sphere, Vec3, World};
    ///
    /// let world = World::build(vec![Sphere::new(Vec3::new(0.0, 0.0, 5.0), 1.0).into()], AccelKind::BvhWide)?;
    /// let rays: Vec<Ray> = (0..5000).map(|i| Ray::new(Vec3::new(i as f32 * 1e-3, 0.0, 0.0), Vec3::Z)).collect();
    /// let mut hits = vec![None; rays.len()];
    /// world.closest_hits(&rays, &mut hits)?;
    /// assert_eq!(hits[0].map(|h| h.t), Some(4.0));
    /// assert!(hits[4999].is_none(), "x = 5 passes beside the sphere");
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn closest_hits(&self, rays: &[Ray], hits: &mut [Option<WorldHit>]) -> Result<(), BatchSizeMismatch> {
        run_batch(rays, hits, |r| self.closest_hit(r, &mut NoCount))
    }

    /// Whether each ray hits anything within its interval, `mask[i]` for `rays[i]`
    /// ([`World::any_hit`]). The two slices must be as long.
    pub fn any_hits(&self, rays: &[Ray], mask: &mut [bool]) -> Result<(), BatchSizeMismatch> {
        run_batch(rays, mask, |r| self.any_hit(r, &mut NoCount))
    }
}
