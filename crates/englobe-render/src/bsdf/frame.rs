//! The local shading frame: an orthonormal basis whose `z` axis is the shading normal, and the
//! change of coordinates between it and the world.
//!
//! From a normal alone the basis is Duff, Burgess, Christensen, Hery, Kensler, Liani and Villemin
//! (2017), "Building an Orthonormal Basis, Revisited" (JCGT 6(1)): one branch on the sign of `z`,
//! and none of the precision loss that Frisvad's earlier construction suffers near `z = -1`.
//! From a normal and a tangent (a mesh's, or a glTF `TANGENT` attribute with its handedness `w`)
//! the tangent is made orthogonal to the normal by one Gram-Schmidt step and the bitangent is
//! `w (n × t)`, as the glTF 2.0 specification defines it for its `TANGENT` attribute.

use englobe::Vec3;

use crate::sampling::orthonormal_frame;

/// An orthonormal basis `(x, y, z)`, `z` the shading normal. Directions given to the BSDFs are
/// expressed in it ([`Frame::to_local`]); the BSDFs' own answers are brought back with
/// [`Frame::from_local`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// First tangent.
    pub x: Vec3,
    /// Second tangent (the bitangent).
    pub y: Vec3,
    /// The normal.
    pub z: Vec3,
}

impl Frame {
    /// The right-handed frame around the unit normal `n` (Duff et al. 2017). `n` must be unit
    /// length; the result is then orthonormal to within a few ulps.
    pub fn from_z(n: Vec3) -> Frame {
        let (x, y) = orthonormal_frame(n);
        Frame { x, y, z: n }
    }

    /// The frame whose `z` is the unit normal `n`, whose `x` is the tangent `t` made orthogonal to
    /// `n`, and whose `y` is `handedness * (n × x)`: glTF's bitangent for `handedness = w` of its
    /// `TANGENT` attribute (`+1` right-handed, `-1` left-handed, the sign alone counts). A tangent
    /// parallel to `n`, zero or not finite falls back to [`Frame::from_z`].
    pub fn from_normal_tangent(n: Vec3, t: Vec3, handedness: f32) -> Frame {
        let x = (t - n * n.dot(t)).normalize_or_zero();
        if x == Vec3::ZERO || !x.is_finite() {
            return Frame::from_z(n);
        }
        let sign = if handedness < 0.0 { -1.0 } else { 1.0 };
        Frame { x, y: n.cross(x) * sign, z: n }
    }

    /// The coordinates of the world vector `v` in this frame.
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.x), v.dot(self.y), v.dot(self.z))
    }

    /// The world vector whose coordinates in this frame are `v`.
    #[inline]
    pub fn from_local(&self, v: Vec3) -> Vec3 {
        self.x * v.x + self.y * v.y + self.z * v.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_orthonormal(f: &Frame) {
        for (u, v) in [(f.x, f.y), (f.x, f.z), (f.y, f.z)] {
            assert!(u.dot(v).abs() < 1e-6, "{f:?}");
        }
        for v in [f.x, f.y, f.z] {
            assert!((v.length() - 1.0).abs() < 1e-6, "{f:?}");
        }
    }

    fn normals() -> Vec<Vec3> {
        let mut ns = vec![Vec3::Z, -Vec3::Z, Vec3::X, -Vec3::Y, Vec3::new(1e-8, 0.0, -1.0).normalize()];
        // Near both poles and across the sign flip at z = 0.
        for z in [-0.999_999f32, -0.5, -1e-7, 0.0, 1e-7, 0.3, 0.999_999] {
            for phi in [0.0f32, 1.0, 2.5, 4.0, 6.0] {
                let r = (1.0 - z * z).max(0.0).sqrt();
                ns.push(Vec3::new(r * phi.cos(), r * phi.sin(), z).normalize());
            }
        }
        ns
    }

    #[test]
    fn frames_from_a_normal_are_right_handed_and_orthonormal() {
        for n in normals() {
            let f = Frame::from_z(n);
            assert_orthonormal(&f);
            assert!((f.x.cross(f.y) - f.z).length() < 1e-6, "right-handed at {n}");
        }
    }

    #[test]
    fn local_and_world_coordinates_round_trip() {
        let v = Vec3::new(0.3, -1.7, 2.2);
        for n in normals() {
            let f = Frame::from_z(n);
            assert!((f.from_local(f.to_local(v)) - v).length() < 1e-5);
            assert!((f.to_local(n) - Vec3::Z).length() < 1e-6, "the normal is local z");
            assert!((f.to_local(v).length() - v.length()).abs() < 1e-5, "lengths are kept");
        }
    }

    #[test]
    fn a_tangent_is_orthogonalised_and_its_handedness_kept() {
        let n = Vec3::new(0.2, 0.3, 0.9).normalize();
        let t = Vec3::new(1.0, 0.1, 0.0); // not orthogonal to n
        let right = Frame::from_normal_tangent(n, t, 1.0);
        assert_orthonormal(&right);
        assert!((right.x.cross(right.y) - n).length() < 1e-6, "w = +1 is right-handed");
        // x lies in the plane of n and t, on t's side.
        assert!(right.x.dot(t) > 0.0 && right.x.dot(n.cross(t)).abs() < 1e-6);
        let left = Frame::from_normal_tangent(n, t, -1.0);
        assert_orthonormal(&left);
        assert_eq!(left.x, right.x);
        assert!((left.y + right.y).length() < 1e-6, "w = -1 flips the bitangent");
        assert!((left.x.cross(left.y) + n).length() < 1e-6);
    }

    #[test]
    fn a_degenerate_tangent_falls_back_to_the_normal_alone() {
        let n = Vec3::new(0.0, 0.6, 0.8);
        for t in [Vec3::ZERO, n * 3.0, Vec3::splat(f32::NAN)] {
            assert_eq!(Frame::from_normal_tangent(n, t, 1.0), Frame::from_z(n), "tangent {t}");
        }
    }
}
