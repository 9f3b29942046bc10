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
//! **Lookups** are bilinear between the pixels' centres, wrapping across the left and right edges
//! (the map is periodic in `φ`) and clamped at the top and bottom rows, so that a map of few
//! pixels shades smoothly instead of in blocks. **Sampling** picks a pixel with probability
//! proportional to the mean of that bilinear reconstruction over the pixel (the luminances of the
//! pixel and its eight neighbours weighted `[1 6 1] / 8` along each axis: the exact integral of
//! the tent-shaped weights over the pixel) times `sin θ`, then a point uniformly inside it. Every
//! direction whose bilinear radiance is not zero lies in a pixel one of whose neighbours is lit,
//! so its density is not zero either. **Densities** are with respect to solid angle: a point of
//! density `p(u, v)` on the map has the density `p(u, v) / (2 π² sin θ)` over directions (the map
//! covers `2π` by `π` radians, and a pixel's solid angle shrinks with `sin θ` towards the poles).
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
                let means = pixel_means(&map.pixels.iter().map(|&p| luminance(p)).collect::<Vec<_>>(), w, h);
                let weights: Vec<f32> =
                    means.iter().enumerate().map(|(i, m)| m * (PI * ((i / w) as f32 + 0.5) / h as f32).sin()).collect();
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

    /// The radiance at map coordinates `uv`, bilinear between pixel centres (maps only).
    fn map_radiance(&self, uv: Vec2) -> Vec3 {
        let Sky::Map(map) = &self.env.sky else { unreachable!("a map's lookup") };
        let (w, h) = (map.width as i64, map.height as i64);
        // Pixel centres sit at half-integers of the continuous coordinates.
        let (px, py) = (uv.x * w as f32 - 0.5, uv.y * h as f32 - 0.5);
        let (fx, fy) = (px - px.floor(), py - py.floor());
        let (x0, y0) = (px.floor() as i64, py.floor() as i64);
        let column = |x: i64| x.rem_euclid(w) as u32;
        let row = |y: i64| y.clamp(0, h - 1) as u32;
        let (xa, xb, ya, yb) = (column(x0), column(x0 + 1), row(y0), row(y0 + 1));
        let top = map.get(xa, ya) * (1.0 - fx) + map.get(xb, ya) * fx;
        let bottom = map.get(xa, yb) * (1.0 - fx) + map.get(xb, yb) * fx;
        (top * (1.0 - fy) + bottom * fy) * self.env.intensity
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
            // At the point that was sampled, whatever rounding the direction went through.
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

/// The mean over each pixel of the bilinear reconstruction of `values` (a `w` x `h` image,
/// wrapping across the left and right edges, clamped at the top and bottom): along each axis, the
/// tent weights of the pixel and its two neighbours integrate over the pixel to `[1 6 1] / 8`.
fn pixel_means(values: &[f32], w: usize, h: usize) -> Vec<f32> {
    let smooth = |a: f32, b: f32, c: f32| (a + 6.0 * b + c) / 8.0;
    let mut rows = vec![0.0; w * h];
    for y in 0..h {
        for x in 0..w {
            let at = |x: usize| values[y * w + x];
            rows[y * w + x] = smooth(at((x + w - 1) % w), at(x), at((x + 1) % w));
        }
    }
    let mut out = vec![0.0; w * h];
    for y in 0..h {
        for x in 0..w {
            let at = |y: usize| rows[y * w + x];
            out[y * w + x] = smooth(at(y.saturating_sub(1)), at(y), at((y + 1).min(h - 1)));
        }
    }
    out
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
    fn lookups_are_bilinear_and_the_rotation_turns_z_towards_x() {
        // 4 x 2: column x, row y holds (x, y, 1); pixel centres at u = (x + 1/2) / 4, v = (y + 1/2) / 2.
        let env = map_env(4, 2, |x, y| Vec3::new(x as f32, y as f32, 1.0), 0.0);
        let light = EnvironmentLight::new(&env);
        let at = |u: f32, v: f32| light.radiance(light.direction(Vec2::new(u, v)));
        let close = |a: Vec3, b: Vec3| (a - b).abs().max_element() < 1e-4;
        for (u, v, want, what) in [
            (0.625, 0.25, Vec3::new(2.0, 0.0, 1.0), "the centre of pixel (2, 0)"),
            (0.75, 0.25, Vec3::new(2.5, 0.0, 1.0), "halfway between columns 2 and 3"),
            (0.6875, 0.5, Vec3::new(2.25, 0.5, 1.0), "a quarter of the way along, halfway down"),
            (0.02, 0.75, Vec3::new(1.5 - 0.16 * 1.5, 1.0, 1.0), "across the left edge, columns 3 and 0"),
            (0.625, 0.05, Vec3::new(2.0, 0.0, 1.0), "above the top row's centres: clamped"),
            (0.625, 0.97, Vec3::new(2.0, 1.0, 1.0), "below the bottom row's centres: clamped"),
        ] {
            assert!(close(at(u, v), want), "{what}: {} against {want}", at(u, v));
        }
        // +x is the map's centre column (u = 1/2), +z a quarter to its right.
        assert!(close(light.radiance(Vec3::X), at(0.5, 0.5)) && close(light.radiance(Vec3::Z), at(0.75, 0.5)));
        // Turned by 90 degrees, what the map shows along +x is seen along -z... (cos 90, 0, -sin 90).
        let turned = EnvironmentLight::new(&map_env(4, 2, |x, y| Vec3::new(x as f32, y as f32, 1.0), 90.0));
        for d in [Vec3::new(1.0, 0.3, 0.02), Vec3::new(0.2, -0.5, 1.0), Vec3::new(-0.7, 0.1, 0.3)] {
            let seen_along = Vec3::new(d.z, d.y, -d.x); // d turned by 90 degrees, +x to -z
            assert!(close(turned.radiance(seen_along), light.radiance(d)), "{d}");
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
                let radiance = light.radiance(s.direction);
                assert!((s.radiance - radiance).abs().max_element() <= 1e-4 * radiance.max_element(), "{radiance}");
            }
        }
        let black = EnvironmentLight::new(&map_env(4, 2, |_, _| Vec3::ZERO, 0.0));
        assert!(black.is_black() && black.sample(Vec2::new(0.5, 0.5)).is_none() && black.pdf(Vec3::X) == 0.0);
    }

    #[test]
    fn every_lit_direction_has_a_density() {
        // One lit pixel in the dark, at the left edge so that its light wraps to the right edge,
        // and one on the top row: the bilinear lookup spreads each over half of its neighbours,
        // and the sampling table covers all of that.
        let env =
            map_env(16, 8, |x, y| if (x, y) == (0, 4) || (x, y) == (9, 0) { Vec3::ONE } else { Vec3::ZERO }, 20.0);
        let light = EnvironmentLight::new(&env);
        let (mut lit, mut dark) = (0, 0);
        for i in 0..400 {
            for j in 0..800 {
                let uv = Vec2::new((j as f32 + 0.5) / 800.0, (i as f32 + 0.5) / 400.0);
                let d = light.direction(uv);
                if light.radiance(d).max_element() > 0.0 {
                    lit += 1;
                    assert!(light.pdf(d) > 0.0, "lit at {uv} with no density");
                } else {
                    dark += 1;
                }
            }
        }
        // The lit share: two pixels' tents, 2 x 2 pixels each of 128, less the top row's clamp.
        assert!(lit > 0 && dark > 0 && (lit as f64 / (lit + dark) as f64) < 8.0 / 128.0, "{lit} {dark}");
        // The table is the bilinear reconstruction's mean over each pixel: [1 6 1] / 8 per axis.
        let means = pixel_means(&[0.0, 8.0, 0.0, 0.0, 0.0, 0.0], 3, 2);
        assert_eq!(means, vec![7.0 / 8.0, 42.0 / 8.0, 7.0 / 8.0, 1.0 / 8.0, 6.0 / 8.0, 1.0 / 8.0]);
    }
}
