//! pbrt's transformation directives as 4x4 matrices (pbrt-v4's `transform.cpp`), in double
//! precision: each directive post-multiplies the current transformation matrix (CTM), so the
//! last one written applies first to an object's points. `Transform` and `ConcatTransform` take
//! the matrix's sixteen numbers column by column (pbrt transposes what it reads), which puts the
//! translation in the last four numbers. `LookAt` is the camera-from-world matrix whose camera
//! space has `x` to the image's right, `y` up and `z` forward (a left-handed frame).

use glam::{DMat4, DVec3, DVec4};

/// Post-multiplies `ctm` by a translation.
pub(super) fn translate(ctm: DMat4, d: DVec3) -> DMat4 {
    ctm * DMat4::from_translation(d)
}

/// Post-multiplies `ctm` by a scale.
pub(super) fn scale(ctm: DMat4, s: DVec3) -> DMat4 {
    ctm * DMat4::from_scale(s)
}

/// Post-multiplies `ctm` by a rotation of `degrees` about `axis` (counter-clockwise looking down
/// the axis, as pbrt's `Rotate`); `None` for a zero axis.
pub(super) fn rotate(ctm: DMat4, degrees: f64, axis: DVec3) -> Option<DMat4> {
    let axis = axis.try_normalize()?;
    Some(ctm * DMat4::from_axis_angle(axis, degrees.to_radians()))
}

/// The matrix of pbrt's sixteen numbers (column by column).
pub(super) fn from_pbrt(numbers: &[f64; 16]) -> DMat4 {
    DMat4::from_cols_array(numbers)
}

/// pbrt's `LookAt`: the camera-from-world matrix of an eye at `eye` looking at `look` with `up`
/// up. Its camera `x` axis is `up x dir` (pbrt's `Cross(up, dir)`), so that the image's right is
/// on the left of a right-handed observer: pbrt's world is left-handed. Fails when the view
/// direction is zero or parallel to `up`.
pub(super) fn look_at(eye: DVec3, look: DVec3, up: DVec3) -> Result<DMat4, String> {
    let dir = (look - eye).try_normalize().ok_or("LookAt: the eye and the point looked at are the same point")?;
    let up = up.try_normalize().ok_or("LookAt: the up vector is zero")?;
    let right = up.cross(dir);
    let Some(right) = right.try_normalize().filter(|_| right.length() > 1e-9) else {
        return Err("LookAt: the up vector is parallel to the viewing direction".into());
    };
    let new_up = dir.cross(right);
    let world_from_camera =
        DMat4::from_cols(right.extend(0.0), new_up.extend(0.0), dir.extend(0.0), DVec4::new(eye.x, eye.y, eye.z, 1.0));
    Ok(world_from_camera.inverse())
}

/// True if `m` maps points affinely (its last row is `0 0 0 1`) and all its numbers are finite.
pub(super) fn is_affine(m: &DMat4) -> bool {
    m.is_finite() && m.row(3) == DVec4::W
}

/// True if the transform swaps handedness (its linear part has a negative determinant), which
/// flips the normal a triangle's winding gives.
pub(super) fn swaps_handedness(m: &DMat4) -> bool {
    glam::DMat3::from_mat4(*m).determinant() < 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_puts_the_eye_at_the_origin_looking_down_z() {
        let m = look_at(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, DVec3::Y).unwrap();
        assert!(m.transform_point3(DVec3::new(0.0, 0.0, 5.0)).length() < 1e-12);
        assert!((m.transform_point3(DVec3::ZERO) - DVec3::new(0.0, 0.0, 5.0)).length() < 1e-12);
        // pbrt's camera x is up x dir = y x -z = -x: looking down -z with y up, world +x is on the
        // image's left.
        assert!((m.transform_vector3(DVec3::X) - DVec3::new(-1.0, 0.0, 0.0)).length() < 1e-12);
        assert!(!swaps_handedness(&m));
        assert!(look_at(DVec3::ZERO, DVec3::Y, DVec3::Y).is_err());
        assert!(look_at(DVec3::ZERO, DVec3::ZERO, DVec3::Y).is_err());
    }

    #[test]
    fn directives_post_multiply_and_matrices_are_read_by_columns() {
        // Translate then Scale: points are scaled first, then moved.
        let m = scale(translate(DMat4::IDENTITY, DVec3::new(1.0, 0.0, 0.0)), DVec3::splat(2.0));
        assert_eq!(m.transform_point3(DVec3::X), DVec3::new(3.0, 0.0, 0.0));
        let r = rotate(DMat4::IDENTITY, 90.0, DVec3::Z).unwrap();
        assert!((r.transform_vector3(DVec3::X) - DVec3::Y).length() < 1e-12);
        assert!(rotate(DMat4::IDENTITY, 90.0, DVec3::ZERO).is_none());
        let mut numbers = [0.0; 16];
        for (i, v) in
            [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, -1.0, 6.8, 1.0].iter().enumerate()
        {
            numbers[i] = *v;
        }
        let m = from_pbrt(&numbers);
        assert!(is_affine(&m) && swaps_handedness(&m));
        assert!(m.transform_point3(DVec3::new(0.0, 1.0, 6.8)).length() < 1e-12);
    }
}
