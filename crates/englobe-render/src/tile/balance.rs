//! Cutting an image by predicted cost instead of area. Strips of equal height can cost very
//! different times (a strip of sky against one through the Sponza's arcades), and a job array
//! waits for its slowest task. A cheap first pass, one centred sample on every 4th pixel of every
//! 4th row with the cost AOV on (nodes visited plus exact tests, see [`crate::cost`]), predicts
//! each row's cost; the strips are then cut where the running total crosses each `K/N` of it.
//!
//! The pass is deterministic (work counts do not depend on threads or order), so every task of a
//! job computes the same cut by itself, and the cut needs no file of its own.

use englobe::World;
use englobe_scene::Scene;

use super::{PixelWindow, TileSpec};
use crate::render::{RenderError, Renderer};

/// Every how many pixels, across and down, the prediction pass samples.
pub const PREDICTION_STRIDE: u32 = 4;

/// The predicted cost of every row of the `scene.image` sized image: the sampled rows' work,
/// each standing for itself and the rows below it up to the next sampled one, plus one unit per
/// pixel (what a pixel costs outside the structure, so that empty rows are not free).
pub fn predict_row_costs(scene: &Scene, world: &World) -> Result<Vec<u64>, RenderError> {
    let (width, height) = (scene.image.width, scene.image.height);
    let out = Renderer::new(scene, world).samples(1).pixel_stride(PREDICTION_STRIDE).record_cost(true).render()?;
    let cost = out.cost.expect("the pass records the cost");
    let sampled_row = |y: u32| -> u64 { (0..width).map(|x| cost.get(x, y)).sum::<u64>() * PREDICTION_STRIDE as u64 };
    Ok((0..height).map(|y| sampled_row(y - y % PREDICTION_STRIDE) + width as u64).collect())
}

impl TileSpec {
    /// The strip of this tile when the rows are cut so that every strip's predicted cost is about
    /// `1/count` of the total (`row_costs` from [`predict_row_costs`]); every strip keeps at least
    /// one row. Refused when there are more strips than rows.
    pub fn balanced_window(&self, width: u32, row_costs: &[u64]) -> Result<PixelWindow, String> {
        // The cut by area refuses more strips than rows.
        self.window(width, row_costs.len() as u32)?;
        let bounds = balanced_cuts(row_costs, self.count);
        Ok(PixelWindow { x0: 0, x1: width, y0: bounds[self.index as usize], y1: bounds[self.index as usize + 1] })
    }
}

/// The `count + 1` row boundaries of the cut: 0, then for each `k` the first row at which the
/// running cost reaches `k / count` of the total, moved so that every strip has a row, then the
/// height. `count` must be at least 1 and at most the number of rows.
fn balanced_cuts(row_costs: &[u64], count: u32) -> Vec<u32> {
    let height = row_costs.len() as u32;
    let total: u128 = row_costs.iter().map(|&c| c as u128).sum();
    let mut cuts = vec![0u32];
    let (mut row, mut running) = (0u32, 0u128);
    for k in 1..count {
        let target = total * k as u128 / count as u128;
        // Leave one row for each strip still to come, and give this one at least one row.
        let lowest = cuts[k as usize - 1] + 1;
        let highest = height - (count - k);
        while row < height && (running < target || row < lowest) && row < highest {
            running += row_costs[row as usize] as u128;
            row += 1;
        }
        cuts.push(row.clamp(lowest, highest));
    }
    cuts.push(height);
    cuts
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_costs_cut_like_the_area() {
        let costs = vec![10; 48];
        for count in [1, 4, 7, 48] {
            let cuts = balanced_cuts(&costs, count);
            assert_eq!(cuts.len(), count as usize + 1);
            for k in 0..count {
                let w = TileSpec { index: k, count }.window(8, 48).unwrap();
                assert!((cuts[k as usize] as i64 - w.y0 as i64).abs() <= 1, "{count}: {cuts:?}");
            }
        }
    }

    #[test]
    fn an_expensive_band_gets_thin_strips_and_every_strip_a_row() {
        // Rows 10..14 cost 100 times the others.
        let costs: Vec<u64> = (0..40).map(|y| if (10..14).contains(&y) { 1000 } else { 10 }).collect();
        let cuts = balanced_cuts(&costs, 4);
        assert_eq!(cuts.first(), Some(&0));
        assert_eq!(cuts.last(), Some(&40));
        assert!(cuts.windows(2).all(|w| w[0] < w[1]), "{cuts:?}");
        let strip = |k: usize| costs[cuts[k] as usize..cuts[k + 1] as usize].iter().sum::<u64>();
        let total: u64 = costs.iter().sum();
        // The band is split: no strip holds much more than a quarter, give or take one row.
        for k in 0..4 {
            assert!(strip(k) <= total / 4 + 1000, "strip {k} costs {} of {total}: {cuts:?}", strip(k));
        }
        // With as many strips as rows, one row each, even when all the cost is at the top.
        let mut top = vec![1u64; 6];
        top[0] = 1_000_000;
        assert_eq!(balanced_cuts(&top, 6), vec![0, 1, 2, 3, 4, 5, 6]);
        assert_eq!(balanced_cuts(&[0, 0, 0], 2), vec![0, 1, 3]);
    }
}
