//! The camera: rays from the eye through the image plane (perspective) or parallel to the view
//! (orthographic), from a pinhole or from a point of a thin lens focused on a plane.
//!
//! The thin lens is pbrt's (Pharr, Jakob and Humphreys, *Physically Based Rendering*, 4th ed.,
//! §5.2.3): the pinhole ray of a pixel meets the plane in focus at one point, and every ray of that
//! pixel starts on the lens and goes through that point, so the plane in focus is sharp and the
//! rest blurs with distance from it. A pinhole camera draws no random numbers for the lens, so its
//! images are those it always gave.

use englobe::{Ray, Vec3};
use englobe_scene::{Camera, Projection};

/// A camera ready to shoot rays into an image of a given size.
#[derive(Clone, Copy, Debug)]
pub struct ImageCamera {
    position: Vec3,
    forward: Vec3,
    /// Image-plane vector from the centre to the right edge: at distance 1 along `forward` for a
    /// perspective camera, in scene units for an orthographic one.
    right: Vec3,
    /// Image-plane vector from the centre to the top edge.
    up: Vec3,
    orthographic: bool,
    lens_radius: f32,
    focus_distance: f32,
    width: f32,
    height: f32,
}

impl ImageCamera {
    /// The camera of the scene for a `width` x `height` image. The scene loader guarantees a
    /// non-degenerate camera (distinct look-at, up not parallel to the view).
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        let forward = (camera.look_at - camera.position).normalize();
        // englobe's frame is right-handed (right = forward x up); pbrt's camera space is
        // left-handed (right = up x forward), and its scenes say so through `left_handed`.
        let (right_dir, up_dir) = if camera.left_handed {
            let right = camera.up.cross(forward).normalize();
            (right, forward.cross(right))
        } else {
            let right = forward.cross(camera.up).normalize();
            (right, right.cross(forward))
        };
        let (half_height, orthographic) = match camera.projection {
            Projection::Perspective => ((camera.fov_degrees.to_radians() * 0.5).tan(), false),
            Projection::Orthographic { view_height } => (view_height * 0.5, true),
        };
        let half_width = half_height * width as f32 / height as f32;
        ImageCamera {
            position: camera.position,
            forward,
            right: right_dir * half_width,
            up: up_dir * half_height,
            orthographic,
            lens_radius: camera.lens_radius,
            focus_distance: camera.focus_distance,
            width: width as f32,
            height: height as f32,
        }
    }

    /// Whether rays start on a lens, so that [`ImageCamera::ray_through_lens`] needs two random
    /// numbers per sample.
    pub fn has_lens(&self) -> bool {
        self.lens_radius > 0.0
    }

    /// The ray through image point `(x, y)`, in pixels from the top-left corner (pixel `(i, j)`
    /// covers `i..i+1` by `j..j+1`), from the centre of the lens. The direction is normalised, so
    /// `t` is a distance.
    #[inline]
    pub fn ray(&self, x: f32, y: f32) -> Ray {
        let sx = 2.0 * x / self.width - 1.0;
        let sy = 1.0 - 2.0 * y / self.height;
        if self.orthographic {
            Ray::new(self.position + self.right * sx + self.up * sy, self.forward)
        } else {
            Ray::new(self.position, (self.forward + self.right * sx + self.up * sy).normalize())
        }
    }

    /// The ray through image point `(x, y)` from the point of the lens that `(u, v)` in `[0, 1)^2`
    /// picks (uniformly over the lens's disk): it meets the centre ray on the plane in focus.
    #[inline]
    pub fn ray_through_lens(&self, x: f32, y: f32, u: f32, v: f32) -> Ray {
        let centre = self.ray(x, y);
        if !self.has_lens() {
            return centre;
        }
        let t = self.focus_distance / centre.dir().dot(self.forward);
        let focus = centre.origin() + centre.dir() * t;
        let (lx, ly) = concentric_disk(u, v);
        let origin = centre.origin() + (self.right.normalize() * lx + self.up.normalize() * ly) * self.lens_radius;
        Ray::new(origin, (focus - origin).normalize())
    }
}

/// Shirley and Chiu's concentric map of the square `[0, 1)^2` onto the unit disk: uniform, and
/// nearby points stay nearby.
fn concentric_disk(u: f32, v: f32) -> (f32, f32) {
    let (a, b) = (2.0 * u - 1.0, 2.0 * v - 1.0);
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    let quarter = std::f32::consts::FRAC_PI_4;
    let (r, theta) = if a.abs() > b.abs() { (a, quarter * (b / a)) } else { (b, 2.0 * quarter - quarter * (a / b)) };
    (r * theta.cos(), r * theta.sin())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> ImageCamera {
        let c = Camera::pinhole(Vec3::ZERO, Vec3::Z, Vec3::Y, 90.0);
        ImageCamera::new(&c, 200, 100)
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

    #[test]
    fn a_left_handed_camera_mirrors_the_right_handed_one() {
        let mut c = Camera::pinhole(Vec3::ZERO, Vec3::Z, Vec3::Y, 90.0);
        c.left_handed = true;
        let cam = ImageCamera::new(&c, 200, 100);
        // Looking along +z with +y up, the left-handed frame puts the image's right at +x.
        assert!((cam.ray(200.0, 50.0).dir() - Vec3::new(2.0, 0.0, 1.0).normalize()).length() < 1e-6);
        assert!((cam.ray(100.0, 0.0).dir() - Vec3::new(0.0, 1.0, 1.0).normalize()).length() < 1e-6);
    }

    #[test]
    fn orthographic_rays_are_parallel_and_span_the_view_height() {
        let mut c = Camera::pinhole(Vec3::new(0.0, 0.0, -10.0), Vec3::ZERO, Vec3::Y, 45.0);
        c.projection = Projection::Orthographic { view_height: 4.0 };
        let cam = ImageCamera::new(&c, 200, 100);
        for (x, y) in [(0.0, 0.0), (100.0, 50.0), (200.0, 100.0), (13.0, 77.0)] {
            assert!((cam.ray(x, y).dir() - Vec3::Z).length() < 1e-6, "({x}, {y})");
        }
        // 100 pixels cover 4 units, so the top edge is 2 units up and the right edge 4 units right.
        assert!((cam.ray(100.0, 0.0).origin() - Vec3::new(0.0, 2.0, -10.0)).length() < 1e-5);
        assert!((cam.ray(200.0, 50.0).origin() - Vec3::new(-4.0, 0.0, -10.0)).length() < 1e-5);
    }

    #[test]
    fn a_point_on_the_focal_plane_is_reached_by_every_lens_sample() {
        let mut c = Camera::pinhole(Vec3::new(1.0, 2.0, -6.0), Vec3::new(0.0, 1.0, 0.0), Vec3::Y, 50.0);
        c.lens_radius = 0.4;
        c.focus_distance = 5.0;
        let cam = ImageCamera::new(&c, 64, 48);
        let forward = (c.look_at - c.position).normalize();
        for (x, y) in [(32.0, 24.0), (3.5, 40.25), (60.0, 1.0)] {
            let centre = cam.ray(x, y);
            let on_plane =
                |r: Ray| r.origin() + r.dir() * ((5.0 - (r.origin() - c.position).dot(forward)) / r.dir().dot(forward));
            let target = on_plane(centre);
            let mut spread = 0f32;
            for i in 0..16 {
                for j in 0..16 {
                    let r = cam.ray_through_lens(x, y, (i as f32 + 0.5) / 16.0, (j as f32 + 0.5) / 16.0);
                    assert!((on_plane(r) - target).length() < 1e-4, "pixel ({x}, {y}), lens sample ({i}, {j})");
                    assert!((r.origin() - c.position).length() <= 0.4 + 1e-5, "the ray starts on the lens");
                    spread = spread.max((r.origin() - c.position).length());
                }
            }
            assert!(spread > 0.35, "the samples cover the lens: {spread}");
        }
    }

    #[test]
    fn off_the_focal_plane_the_lens_blurs_by_the_thin_lens_law() {
        // A point at distance d on the axis, focus at f, lens radius a: the circle of confusion on
        // the focal plane has radius a |d - f| / d.
        let mut c = Camera::pinhole(Vec3::ZERO, Vec3::Z, Vec3::Y, 40.0);
        (c.lens_radius, c.focus_distance) = (0.5, 4.0);
        let cam = ImageCamera::new(&c, 100, 100);
        // Rays from the lens's edge through the centre pixel's focus point cross z = 8 at a
        // distance a (8 - 4) / 4 = a from the axis.
        let r = cam.ray_through_lens(50.0, 50.0, 1.0 - 1e-7, 0.5);
        let at = r.origin() + r.dir() * ((8.0 - r.origin().z) / r.dir().z);
        assert!((at.truncate().length() - 0.5).abs() < 1e-3, "{at}");
    }
}
