//! Morton codes: points of a box mapped to positions along the Z-order space-filling curve, by
//! interleaving the bits of their quantised coordinates (Morton (1966), "A Computer Oriented
//! Geodetic Data Base and a New Technique in File Sequencing", IBM). Sorting primitives by the
//! code of their centroid puts primitives close in space close in the list, which is what the
//! agglomerative builder ([`super::ploc`]) searches its neighbours in. The bit spreading is the
//! usual shift-and-mask sequence (pbrt's `EncodeMorton3`; Karras (2012), "Maximizing Parallelism
//! in the Construction of BVHs, Octrees, and k-d Trees").

use glam::Vec3;

use crate::Aabb;

/// Bits per axis: 3 x 21 = 63 bits of a `u64`.
pub const BITS_PER_AXIS: u32 = 21;
/// Largest quantised coordinate.
const MAX_CELL: u32 = (1 << BITS_PER_AXIS) - 1;

/// The 21 low bits of `x` moved to every third bit of the result (bit `i` to bit `3 i`).
#[inline]
pub fn spread_bits(x: u32) -> u64 {
    let mut x = (x & MAX_CELL) as u64;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// The Morton code of a cell: `x` in the lowest bit of each triple, then `y`, then `z`.
#[inline]
pub fn interleave(x: u32, y: u32, z: u32) -> u64 {
    spread_bits(x) | spread_bits(y) << 1 | spread_bits(z) << 2
}

/// Maps the points of a box to Morton codes on a grid of `2^21` cells per axis.
#[derive(Clone, Copy, Debug)]
pub struct MortonGrid {
    min: Vec3,
    /// Cells per unit along each axis (0 along an axis where the box is flat).
    scale: Vec3,
}

impl MortonGrid {
    /// The grid over `bounds`.
    pub fn new(bounds: &Aabb) -> Self {
        let extent = bounds.extent();
        let cells = MAX_CELL as f32;
        let scale = Vec3::from_array(extent.to_array().map(|e| if e > 0.0 { cells / e } else { 0.0 }));
        MortonGrid { min: bounds.min, scale }
    }

    /// The code of `p`. Points outside the box, infinite or NaN coordinates are clamped to the
    /// grid (NaN to its first cell) rather than rejected.
    #[inline]
    pub fn code(&self, p: Vec3) -> u64 {
        let q = (p - self.min) * self.scale;
        // `as u32` saturates and maps NaN to 0.
        let cell = |v: f32| (v as u32).min(MAX_CELL);
        interleave(cell(q.x), cell(q.y), cell(q.z))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bits_are_interleaved() {
        assert_eq!(spread_bits(0b111), 0b1001001);
        assert_eq!(spread_bits(MAX_CELL), 0x1249_2492_4924_9249);
        assert_eq!(interleave(1, 0, 0), 1);
        assert_eq!(interleave(0, 1, 0), 2);
        assert_eq!(interleave(0, 0, 1), 4);
        assert_eq!(interleave(MAX_CELL, MAX_CELL, MAX_CELL), (1u64 << 63) - 1);
        // Every bit of x lands where it should.
        for bit in 0..BITS_PER_AXIS {
            assert_eq!(interleave(1 << bit, 0, 0), 1u64 << (3 * bit));
        }
    }

    #[test]
    fn codes_follow_the_z_curve_and_clamp() {
        let grid = MortonGrid::new(&Aabb::new(Vec3::ZERO, Vec3::ONE));
        assert_eq!(grid.code(Vec3::ZERO), 0);
        assert_eq!(grid.code(Vec3::ONE), (1u64 << 63) - 1);
        // The lower half along z comes before the upper half, whatever x and y.
        assert!(grid.code(Vec3::new(0.9, 0.9, 0.4)) < grid.code(Vec3::new(0.1, 0.1, 0.6)));
        assert_eq!(grid.code(Vec3::splat(-5.0)), 0);
        assert_eq!(grid.code(Vec3::splat(f32::NAN)), 0);
        assert_eq!(grid.code(Vec3::splat(f32::INFINITY)), (1u64 << 63) - 1);
        // A flat box: the flat axis contributes nothing.
        let flat = MortonGrid::new(&Aabb::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0)));
        assert_eq!(flat.code(Vec3::new(0.0, 0.0, 3.0)), 0);
    }
}
