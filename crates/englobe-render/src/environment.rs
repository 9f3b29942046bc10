//! The environment as a light: the radiance of every direction, and directions sampled in
//! proportion to it (importance sampling of an environment map by a piecewise-constant 2D
//! distribution over its pixels' luminance times `sin θ`, Pharr, Jakob and Humphreys, "Physically
//! Based Rendering", 3rd ed., section 14.2.4, "Infinite Area Lights").
//!
//! **Directions and the map.** A direction `(x, y, z)` of the environment's own frame has the polar
//! angle `θ = acos(y)` from +y and the azimuth `φ = atan2(z, x)`; it is seen at
//! `u = 1/2 + φ / 2π` across the map (0 at its left edge) and `v = θ / π` down it (0 at its top
//! row). So the top row is straight up, the centre column (`u = 1/2`) looks along +x, `u = 3/4`
//! along +z, and the left and right edges along -x: Blender's layout of an equirectangular world
//! texture, once its z-up world is turned y-up as glTF exporters turn it. The environment's
//! `rotation` turns the map about +y (+z towards +x) before it is seen: a world direction is first
//! turned back by the rotation, then mapped. [`direction_to_uv`] and [`uv_to_direction`] are the
//! two ways.
//!
//! **Lookups** are nearest-pixel: the radiance is constant over each pixel, exactly as the
//! sampling density is, so that every direction whose radiance is not zero has a density that is
//! not zero. **Densities** are with respect to solid angle: a point of density `p(u, v)` on the map
//! has the density `p(u, v) / (2 π² sin θ)` over directions (the map covers `2π` by `π` radians,
//! and a pixel's solid angle shrinks with `sin θ` towards the poles).
//!
//! A constant colour and the sky gradient are exact functions of the direction; they are sampled
//! through a table of 64 rows (they do not depend on the azimuth) of the largest radiance in each
//! row, which keeps the density positive wherever the radiance is.

use std::f32::consts::PI;

use englobe::{Vec2, Vec3};
use englobe_scene::{Environment, Sky};

use crate::distribution::Distribution2D;

/// Rows of the table that samples a constant or gradient sky.
const SKY_ROWS: usize = 64;

/// The luminance of a linear Rec. 709 colour (ITU-R BT.709 weights).
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// The map coordinates `(u, v)`, each in `[0, 1]`, of a unit direction of the map's own frame.
pub fn direction_to_uv(d: Vec3) -> Vec2 {
    let phi = d.z.atan2(d.x);
    let theta = d.y.clamp(-1.0, 1.0).acos();
    Vec2::new(0.5 + phi / (2.0 * PI), theta / PI)
}

/// The unit direction of the map's own frame seen at map coordinates `(u, v)`.
pub fn uv_to_direction(uv: Vec2) -> Vec3 {
    let phi = 2.0 * PI * (uv.x - 0.5);
    let theta = PI * uv.y;
    let (sin_t, cos_t) = theta.sin_cos();
    let (sin_p, cos_p) = phi.sin_cos();
    Vec3::new(sin_t * cos_p, cos_t, sin_t * sin_p)
}

/// A direction sampled on the environment.
#[derive(Clone, Copy, Debug)]
pub struct EnvironmentSample {
    /// The unit direction towards the environment, in the world.
    pub direction: Vec3,
    /// The radiance arriving from it.
    pub radiance: Vec3,
    /// Its density with respect to solid angle.
    pub pdf: f32,
}

/// The environment of a scene, ready for lookups and sampling.
#[derive(Clone, Debug)]
pub struct EnvironmentLight {
    env: Environment,
    /// Cosine and sine of the rotation about +y.
    cos_r: f32,
    sin_r: f32,
    /// Columns and rows of the sampling table (the map's pixels, or one column for a sky).
    columns: usize,
    rows: usize,
    distribution: Distribution2D,
}

impl EnvironmentLight {
    /// The light of `env`, with its sampling table.
    pub fn new(env: &Environment) -> Self {
        let (sin_r, cos_r) = env.rotation_degrees.to_radians().sin_cos();
        let (columns, rows, weights) = match &env.sky {
            Sky::Map(map) => {
                let (w, h) = (map.width as usize, map.height as usize);
                let mut weights = Vec::with_capacity(w * h);
                for y in 0..h {
                    let sin_theta = (PI * (y as f32 + 0.5) / h as f32).sin();
                    weights.extend(map.pixels[y * w..(y + 1) * w].iter().map(|&p| luminance(p) * sin_theta));
                }
                (w, h, weights)
            }
            sky => {
                let weights = (0..SKY_ROWS)
                    .map(|row| {
                        let at = |v: f32| luminance(sky_radiance(sky, uv_to_direction(Vec2::new(0.5, v)).y));
                        let (top, bottom) = (row as f32 / SKY_ROWS as f32, (row + 1) as f32 / SKY_ROWS as f32);
                        // A sky's radiance is linear in y within a row: its largest is at an end.
                        let largest = at(top).max(at(bottom)).max(at(0.5 * (top + bottom)));
                        largest * (PI * (row as f32 + 0.5) / SKY_ROWS as f32).sin()
                    })
                    .collect();
                (1, SKY_ROWS, weights)
            }
        };
        let weights: Vec<f32> = weights.into_iter().map(|w| w * env.intensity).collect();
        let distribution = Distribution2D::new(&weights, columns, rows);
        EnvironmentLight { env: env.clone(), cos_r, sin_r, columns, rows, distribution }
    }

    /// True if the environment sends no light at all (nothing to sample).
    pub fn is_black(&self) -> bool {
        !(self.distribution.integral() > 0.0)
    }

    /// The direction of the map's own frame that the world direction `d` sees.
    fn to_local(&self, d: Vec3) -> Vec3 {
        Vec3::new(d.x * self.cos_r - d.z * self.sin_r, d.y, d.x * self.sin_r + d.z * self.cos_r)
    }

    /// The world direction of the map's own direction `l`.
    fn to_world(&self, l: Vec3) -> Vec3 {
        Vec3::new(l.x * self.cos_r + l.z * self.sin_r, l.y, -l.x * self.sin_r + l.z * self.cos_r)
    }

    /// The map coordinates `(u, v)` that the world direction `d` (any length) sees.
    pub fn uv(&self, d: Vec3) -> Vec2 {
        direction_to_uv(self.to_local(d.normalize()))
    }

    /// The world direction seen at map coordinates `uv`.
    pub fn direction(&self, uv: Vec2) -> Vec3 {
        self.to_world(uv_to_direction(uv))
    }

    /// The radiance arriving from the world direction `d` (any length, not zero).
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        let local = self.to_local(d.normalize());
        match &self.env.sky {
            Sky::Map(_) => self.map_radiance(direction_to_uv(local)),
            sky => sky_radiance(sky, local.y) * self.env.intensity,
        }
    }

    /// The radiance at map coordinates `uv`, nearest pixel (maps only).
    fn map_radiance(&self, uv: Vec2) -> Vec3 {
        let Sky::Map(map) = &self.env.sky else { unreachable!("a map's lookup") };
        let x = ((uv.x * map.width as f32) as u32).min(map.width - 1);
        let y = ((uv.y * map.height as f32) as u32).min(map.height - 1);
        map.get(x, y) * self.env.intensity
    }

    /// A direction from two uniform numbers in `[0, 1)`, with density proportional to the
    /// table's weights; `None` where the environment is black (or at a pole, where the density
    /// over directions is not defined).
    pub fn sample(&self, u: Vec2) -> Option<EnvironmentSample> {
        let ([su, sv], pdf_uv) = self.distribution.sample(u.x, u.y);
        let sin_theta = (PI * sv).sin();
        if !(pdf_uv > 0.0 && sin_theta > 0.0) {
            return None;
        }
        let uv = Vec2::new(su, sv);
        let direction = self.direction(uv);
        let radiance = match &self.env.sky {
            // The pixel that was sampled, whatever rounding the direction went through.
            Sky::Map(_) => self.map_radiance(uv),
            sky => sky_radiance(sky, uv_to_direction(uv).y) * self.env.intensity,
        };
        Some(EnvironmentSample { direction, radiance, pdf: pdf_uv / (2.0 * PI * PI * sin_theta) })
    }

    /// The density of [`EnvironmentLight::sample`] at the world direction `d` (any length), with
    /// respect to solid angle.
    pub fn pdf(&self, d: Vec3) -> f32 {
        let local = self.to_local(d.normalize());
        // From x and z rather than 1 - y², which cancels near the poles.
        let sin_theta = local.x.hypot(local.z);
        if !(sin_theta > 0.0) {
            return 0.0;
        }
        let uv = direction_to_uv(local);
        self.distribution.pdf(uv.x, uv.y) / (2.0 * PI * PI * sin_theta)
    }

    /// Columns and rows of the sampling table.
    pub fn table_size(&self) -> (usize, usize) {
        (self.columns, self.rows)
    }
}

/// The radiance of a constant or gradient sky in a direction whose `y` is given (before the
/// environment's intensity).
fn sky_radiance(sky: &Sky, y: f32) -> Vec3 {
    match *sky {
        Sky::Constant(c) => c,
        Sky::Gradient { zenith, horizon, ground } => {
            if y >= 0.0 {
                horizon + (zenith - horizon) * y.min(1.0)
            } else {
                ground
            }
        }
        Sky::Map(_) => unreachable!("maps are looked up by pixel"),
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use englobe_scene::EnvironmentMap;

    use super::*;

    fn map_env(width: u32, height: u32, pixel: impl Fn(u32, u32) -> Vec3, rotation: f32) -> Environment {
        let pixels = (0..height).flat_map(|y| (0..width).map(move |x| (x, y))).map(|(x, y)| pixel(x, y)).collect();
        let map = EnvironmentMap { path: "test.exr".into(), width, height, pixels };
        Environment { sky: Sky::Map(Arc::new(map)), intensity: 1.0, rotation_degrees: rotation }
    }

    #[test]
    fn the_map_layout_is_the_documented_one() {
        let close = |a: Vec2, b: Vec2| (a - b).length() < 1e-6;
        assert!(close(direction_to_uv(Vec3::X), Vec2::new(0.5, 0.5)), "+x at the centre");
        assert!(close(direction_to_uv(Vec3::Z), Vec2::new(0.75, 0.5)), "+z a quarter right");
        assert!(close(direction_to_uv(-Vec3::Z), Vec2::new(0.25, 0.5)));
        assert_eq!(direction_to_uv(Vec3::Y).y, 0.0, "straight up on the top row");
        assert_eq!(direction_to_uv(-Vec3::Y).y, 1.0);
        assert!(
            direction_to_uv(Vec3::new(-1.0, 0.0, 1e-6)).x > 0.99
                && direction_to_uv(Vec3::new(-1.0, 0.0, -1e-6)).x < 0.01
        );
        for (u, v) in [(0.1, 0.2), (0.5, 0.5), (0.77, 0.91), (0.99, 0.01)] {
            let uv = Vec2::new(u, v);
            assert!(close(direction_to_uv(uv_to_direction(uv)), uv), "{uv}");
            assert!((uv_to_direction(uv).length() - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn lookups_are_nearest_pixel_and_the_rotation_turns_z_towards_x() {
        // 4 x 2: column x, row y holds (x, y, 1).
        let env = map_env(4, 2, |x, y| Vec3::new(x as f32, y as f32, 1.0), 0.0);
        let light = EnvironmentLight::new(&env);
        // +x, slightly up: the centre column is the start of column 2, top row.
        assert_eq!(light.radiance(Vec3::new(1.0, 0.1, 0.01)), Vec3::new(2.0, 0.0, 1.0));
        assert_eq!(light.radiance(Vec3::new(0.0, -0.1, 1.0)), Vec3::new(3.0, 1.0, 1.0), "+z: column 3");
        assert_eq!(light.radiance(Vec3::new(-0.01, 0.1, -1.0)), Vec3::new(0.0, 0.0, 1.0), "-z: column 0 of the map");
        // Turned by 90 degrees, what the map shows along +x is seen along -z... (cos 90, 0, -sin 90).
        let turned = EnvironmentLight::new(&map_env(4, 2, |x, y| Vec3::new(x as f32, y as f32, 1.0), 90.0));
        for d in [Vec3::new(1.0, 0.3, 0.02), Vec3::new(0.2, -0.5, 1.0), Vec3::new(-0.7, 0.1, 0.3)] {
            let seen_along = Vec3::new(d.z, d.y, -d.x); // d turned by 90 degrees, +x to -z
            assert_eq!(turned.radiance(seen_along), light.radiance(d), "{d}");
        }
        let sky = Environment {
            sky: Sky::Gradient { zenith: Vec3::new(0.0, 0.0, 2.0), horizon: Vec3::ONE, ground: Vec3::ZERO },
            intensity: 3.0,
            rotation_degrees: 0.0,
        };
        let light = EnvironmentLight::new(&sky);
        assert_eq!(light.radiance(Vec3::Y), Vec3::new(0.0, 0.0, 6.0));
        assert!((light.radiance(Vec3::new(1.0, 1.0, 0.0)) - Vec3::new(0.87868, 0.87868, 5.12132)).length() < 1e-4);
        assert_eq!(light.radiance(Vec3::new(1.0, -0.01, 0.0)), Vec3::ZERO);
    }

    /// The integral of `f` over the sphere by the midpoint rule on `n` x `2n` cells in (θ, φ),
    /// with the solid angle `sin θ dθ dφ`; with `n` a multiple of the map's rows, the cells' edges
    /// fall on the pixels' edges.
    fn integrate(n: usize, f: impl Fn(Vec3) -> f64) -> f64 {
        let step = std::f64::consts::PI / n as f64;
        let mut sum = 0.0;
        for i in 0..n {
            let theta = (i as f64 + 0.5) * step;
            let (sin_t, cos_t) = theta.sin_cos();
            for j in 0..2 * n {
                let phi = (j as f64 + 0.5) * step;
                sum += f(Vec3::new((sin_t * phi.cos()) as f32, cos_t as f32, (sin_t * phi.sin()) as f32)) * sin_t;
            }
        }
        sum * step * step
    }

    #[test]
    fn densities_integrate_to_one_over_the_sphere() {
        let sun =
            map_env(32, 16, |x, y| if (x, y) == (20, 5) { Vec3::splat(500.0) } else { Vec3::new(0.2, 0.3, 1.0) }, 45.0);
        let sky = Environment {
            sky: Sky::Gradient { zenith: Vec3::new(0.1, 0.2, 1.0), horizon: Vec3::ONE, ground: Vec3::splat(0.1) },
            intensity: 2.0,
            rotation_degrees: 0.0,
        };
        let constant = Environment { sky: Sky::Constant(Vec3::ONE), intensity: 1.0, rotation_degrees: 0.0 };
        for env in [sun, sky, constant] {
            let light = EnvironmentLight::new(&env);
            let total = integrate(640, |d| light.pdf(d) as f64);
            assert!((total - 1.0).abs() < 1e-4, "{:?}: {total}", env.sky);
        }
    }

    #[test]
    fn samples_carry_the_density_and_radiance_of_their_direction() {
        let env = map_env(32, 16, |x, y| Vec3::new(1.0 + x as f32, 0.5, y as f32 * 0.1), -75.0);
        let light = EnvironmentLight::new(&env);
        let mut rng = 12345u64;
        let mut next = || {
            rng = rng.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (rng >> 40) as f32 / (1u64 << 24) as f32
        };
        for _ in 0..2000 {
            let s = light.sample(Vec2::new(next(), next())).unwrap();
            assert!((s.direction.length() - 1.0).abs() < 1e-5);
            // Away from pixel edges (where rounding may cross into the neighbour) the direction
            // has the density and the radiance of the pixel sampled.
            let uv = light.uv(s.direction) * Vec2::new(32.0, 16.0);
            if (uv - uv.round()).abs().min_element() > 1e-3 {
                let pdf = light.pdf(s.direction);
                assert!((s.pdf - pdf).abs() <= 1e-4 * pdf, "{} against {pdf}", s.pdf);
                assert_eq!(s.radiance, light.radiance(s.direction));
            }
        }
        let black = EnvironmentLight::new(&map_env(4, 2, |_, _| Vec3::ZERO, 0.0));
        assert!(black.is_black() && black.sample(Vec2::new(0.5, 0.5)).is_none() && black.pdf(Vec3::X) == 0.0);
    }
}
