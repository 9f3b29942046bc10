//! The pinhole perspective camera: one ray from the eye through each point of the image plane.

use englobe::{Ray, Vec3};
use englobe_scene::Camera;

/// A camera ready to shoot rays into an image of a given size.
#[derive(Clone, Copy, Debug)]
pub struct PinholeCamera {
    position: Vec3,
    forward: Vec3,
    /// Image-plane vector from the centre to the right edge, at distance 1 along `forward`.
    right: Vec3,
    /// Image-plane vector from the centre to the top edge.
    up: Vec3,
    width: f32,
    height: f32,
}

impl PinholeCamera {
    /// The camera of the scene for a `width` x `height` image. The scene loader guarantees a
    /// non-degenerate camera (distinct look-at, up not parallel to the view).
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        let forward = (camera.look_at - camera.position).normalize();
        let right_dir = forward.cross(camera.up).normalize();
        let up_dir = right_dir.cross(forward);
        let half_height = (camera.fov_degrees.to_radians() * 0.5).tan();
        let half_width = half_height * width as f32 / height as f32;
        PinholeCamera {
            position: camera.position,
            forward,
            right: right_dir * half_width,
            up: up_dir * half_height,
            width: width as f32,
            height: height as f32,
        }
    }

    /// The ray through image point `(x, y)`, in pixels from the top-left corner (pixel `(i, j)`
    /// covers `i..i+1` by `j..j+1`). The direction is normalised, so `t` is a distance.
    #[inline]
    pub fn ray(&self, x: f32, y: f32) -> Ray {
        let sx = 2.0 * x / self.width - 1.0;
        let sy = 1.0 - 2.0 * y / self.height;
        let dir = (self.forward + self.right * sx + self.up * sy).normalize();
        Ray::new(self.position, dir)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> PinholeCamera {
        let c = Camera { position: Vec3::ZERO, look_at: Vec3::Z, up: Vec3::Y, fov_degrees: 90.0 };
        PinholeCamera::new(&c, 200, 100)
    }

    #[test]
    fn centre_looks_forward() {
        let r = cam().ray(100.0, 50.0);
        assert!((r.dir() - Vec3::Z).length() < 1e-6);
    }

    #[test]
    fn top_edge_is_at_half_the_field_of_view() {
        let r = cam().ray(100.0, 0.0);
        assert!((r.dir() - Vec3::new(0.0, 1.0, 1.0).normalize()).length() < 1e-6);
    }

    #[test]
    fn right_of_the_image_is_right_of_the_camera() {
        // Looking along +z with +y up, a right-handed frame puts the image's right at -x.
        let r = cam().ray(200.0, 50.0);
        assert!((r.dir() - Vec3::new(-2.0, 0.0, 1.0).normalize()).length() < 1e-6);
    }
}
