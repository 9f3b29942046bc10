//! Where a ray meets one primitive: the answer of every exact test, and what the acceleration
//! structures' contract passes around.

/// Where a ray meets one primitive: its parameter `t` and two surface coordinates (barycentric
/// weights of the second and third vertex for triangles, zero for other shapes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrimHit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// First surface coordinate.
    pub u: f32,
    /// Second surface coordinate.
    pub v: f32,
}

impl PrimHit {
    /// A hit with no surface coordinates.
    #[inline(always)]
    pub fn at(t: f32) -> Self {
        PrimHit { t, u: 0.0, v: 0.0 }
    }
}
