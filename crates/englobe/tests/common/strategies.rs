//! Proptest strategies that several tests draw their geometry from: coordinates (some on the grid
//! of integers, where vertices and edges meet exactly), points, and small triangles with
//! degenerate ones among them.

use englobe::Vec3;
use proptest::prelude::*;

/// A coordinate in `-4..4`, an integer one time in four.
pub fn coord() -> impl Strategy<Value = f32> {
    prop_oneof![3 => -4.0f32..4.0, 1 => (-4i32..=4).prop_map(|i| i as f32)]
}

/// A point of such coordinates.
pub fn point() -> impl Strategy<Value = Vec3> {
    (coord(), coord(), coord()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// Small triangles, and degenerate ones: a repeated vertex, or three points on a line.
pub fn triangle() -> impl Strategy<Value = [Vec3; 3]> {
    prop_oneof![
        8 => (point(), point(), point()).prop_map(|(a, b, c)| [a, a + (b - a) * 0.4, a + (c - a) * 0.4]),
        1 => (point(), point()).prop_map(|(a, b)| [a, b, a]),
        1 => (point(), point()).prop_map(|(a, b)| [a, b, a + (b - a) * 2.0]),
    ]
}
