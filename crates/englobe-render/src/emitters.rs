//! Emissive triangles as area lights: the path tracer samples a point on them directly
//! (next-event estimation) instead of waiting for a bounce to find them, which is what turns a
//! small bright lamp from a rain of fireflies into smooth light.
//!
//! A triangle is chosen with probability proportional to its area and a point uniformly on it
//! (Turk 1990; Pharr, Jakob and Humphreys, "Physically Based Rendering", section 13.6.4), so the
//! density of a sampled point is `1 / total area` over all emissive triangles. Light sampling and
//! the bounces that hit an emitter by chance are combined with the power heuristic of Veach and
//! Guibas (1995), "Optimally Combining Sampling Techniques for Monte Carlo Rendering".
//! Emissive spheres, boxes and planes are not sampled; bounces find them, with full weight; so
//! are triangles whose emission comes from a texture.

use englobe::{Object, Shape, Vec3};
use englobe_scene::{Material, Scene};

/// One emissive triangle in world space.
#[derive(Clone, Copy, Debug)]
struct EmissiveTriangle {
    v0: Vec3,
    e1: Vec3,
    e2: Vec3,
    emission: Vec3,
}

/// A point sampled on an emitter.
#[derive(Clone, Copy, Debug)]
pub struct EmitterSample {
    /// The point.
    pub point: Vec3,
    /// The unit normal of its triangle, on the side that emits (the winding's).
    pub normal: Vec3,
    /// The emitted radiance.
    pub emission: Vec3,
}

/// Every emissive triangle of a scene, with the cumulative areas that sampling searches.
#[derive(Clone, Debug, Default)]
pub struct Emitters {
    triangles: Vec<EmissiveTriangle>,
    /// `cumulative[i]` is the area of triangles `0..=i`.
    cumulative: Vec<f64>,
    total_area: f64,
}

impl Emitters {
    /// The emissive triangles of `scene`: scene triangles, mesh triangles and triangles of
    /// instanced meshes whose material emits light.
    pub fn of(scene: &Scene) -> Self {
        let mut emitters = Emitters::default();
        for object in &scene.objects {
            let emission = |prim: u32| {
                let m = &scene.materials[object.material_of(prim) as usize];
                if Emitters::samples(m) { m.emission } else { Vec3::ZERO }
            };
            match &object.object {
                Object::Shape(Shape::Triangle(t)) => emitters.push(t.vertices, emission(0)),
                Object::Mesh(m) => {
                    for i in 0..m.len() as u32 {
                        emitters.push(m.triangle(i).vertices, emission(i));
                    }
                }
                Object::Instance(inst) => {
                    let m = inst.mesh();
                    for i in 0..m.len() as u32 {
                        let v = m.triangle(i).vertices.map(|p| inst.to_world().transform_point3(p));
                        emitters.push(v, emission(i));
                    }
                }
                Object::Shape(_) => {}
            }
        }
        emitters
    }

    fn push(&mut self, [a, b, c]: [Vec3; 3], emission: Vec3) {
        let area = 0.5 * (b - a).cross(c - a).length() as f64;
        if emission == Vec3::ZERO || !(area > 0.0) || !area.is_finite() {
            return;
        }
        self.total_area += area;
        self.cumulative.push(self.total_area);
        self.triangles.push(EmissiveTriangle { v0: a, e1: b - a, e2: c - a, emission });
    }

    /// Whether the triangles of material `m` are sampled when they emit: not when an emission
    /// texture varies their radiance over the surface (sampling by area with the factor alone
    /// would be biased), which leaves them to the bounces that hit them.
    pub fn samples(m: &Material) -> bool {
        m.textures.emission.is_none()
    }

    /// True if there is nothing to sample.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// A point on the emitters from three uniform numbers in `[0, 1)`; its density with respect
    /// to area is [`Emitters::area_pdf`].
    pub fn sample(&self, u0: f32, u1: f32, u2: f32) -> Option<EmitterSample> {
        let target = u0 as f64 * self.total_area;
        let i = self.cumulative.partition_point(|&c| c <= target).min(self.triangles.len().checked_sub(1)?);
        let t = &self.triangles[i];
        let su = u1.sqrt();
        let point = t.v0 + t.e1 * (su * (1.0 - u2)) + t.e2 * (su * u2);
        Some(EmitterSample { point, normal: t.e1.cross(t.e2).normalize(), emission: t.emission })
    }

    /// Density of [`Emitters::sample`] with respect to area: one over the total emissive area.
    pub fn area_pdf(&self) -> f32 {
        if self.total_area > 0.0 { (1.0 / self.total_area) as f32 } else { 0.0 }
    }
}

/// The power heuristic weight of a sample of density `pdf` against another technique's `other`
/// (Veach and Guibas 1995): `pdf^2 / (pdf^2 + other^2)`, computed from the ratio of the two, so
/// that a density whose square overflows `f32` (a light seen at a grazing angle from a point a
/// million units away on an infinite plane has a density of 5e19) weighs 1, not `inf / inf`.
pub fn power_heuristic(pdf: f32, other: f32) -> f32 {
    if !(pdf > 0.0) {
        return 0.0;
    }
    let r = other / pdf;
    if r.is_nan() {
        // Both infinite: as likely as each other.
        return 0.5;
    }
    1.0 / (1.0 + r * r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_power_heuristic_never_gives_nan() {
        assert_eq!(power_heuristic(1.0, 1.0), 0.5);
        assert!((power_heuristic(3.0, 1.0) - 0.9).abs() < 1e-6);
        assert_eq!(power_heuristic(0.0, 1.0), 0.0);
        assert_eq!(power_heuristic(0.0, 0.0), 0.0);
        assert_eq!(power_heuristic(2.0, 0.0), 1.0);
        // Densities whose squares overflow f32 (the naive form gives inf / inf).
        assert_eq!(power_heuristic(4.9e19, 5.8e-9), 1.0);
        assert!(power_heuristic(5.8e-9, 4.9e19) < 1e-30);
        assert!((power_heuristic(3e20, 1e20) - 0.9).abs() < 1e-6);
        assert_eq!(power_heuristic(f32::INFINITY, f32::INFINITY), 0.5);
        assert_eq!(power_heuristic(f32::INFINITY, 1.0), 1.0);
        assert_eq!(power_heuristic(f32::NAN, 1.0), 0.0);
    }

    #[test]
    fn points_are_chosen_in_proportion_to_area() {
        let mut e = Emitters::default();
        e.push([Vec3::ZERO, Vec3::X, Vec3::Y], Vec3::ONE); // area 0.5
        e.push([Vec3::Z, Vec3::Z + Vec3::X * 3.0, Vec3::Z + Vec3::Y], Vec3::ONE); // area 1.5
        e.push([Vec3::ZERO, Vec3::X, Vec3::X * 2.0], Vec3::ONE); // degenerate: ignored
        e.push([Vec3::ZERO, Vec3::X, Vec3::Y], Vec3::ZERO); // dark: ignored
        assert_eq!(e.triangles.len(), 2);
        assert_eq!(e.area_pdf(), 0.5);
        let n = 1000;
        let on_second = (0..n).filter(|i| e.sample((*i as f32 + 0.5) / n as f32, 0.3, 0.6).unwrap().point.z == 1.0);
        assert_eq!(on_second.count(), 750);
    }

    #[test]
    fn points_lie_on_their_triangle() {
        let mut e = Emitters::default();
        e.push([Vec3::new(1.0, 0.0, 0.0), Vec3::new(3.0, 0.0, 0.0), Vec3::new(1.0, 2.0, 0.0)], Vec3::ONE);
        for (u1, u2) in [(0.0, 0.0), (0.999, 0.0), (0.999, 0.999), (0.5, 0.5)] {
            let s = e.sample(0.2, u1, u2).unwrap();
            let p = s.point;
            assert!(p.z == 0.0 && p.x >= 1.0 && p.y >= 0.0 && (p.x - 1.0) + p.y <= 2.0 + 1e-5, "{p}");
            assert_eq!(s.normal, Vec3::Z);
        }
        assert!(Emitters::default().sample(0.5, 0.5, 0.5).is_none());
    }

    #[test]
    fn power_heuristic_weights_sum_to_one() {
        let (a, b) = (0.3, 1.7);
        assert!((power_heuristic(a, b) + power_heuristic(b, a) - 1.0).abs() < 1e-6);
        assert_eq!(power_heuristic(0.0, 0.0), 0.0);
    }
}
