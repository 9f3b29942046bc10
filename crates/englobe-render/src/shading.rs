//! What both integrators need at a hit: the surface frame (point, normals facing the incoming
//! ray, material) and the light arriving from each point or directional light, with the shadow
//! ray that decides whether it arrives.
//!
//! Light units follow the Whitted convention of the scene format: a white diffuse surface facing
//! a point light of intensity `I` at distance `d` reflects `I / d²`, so a diffuse surface's
//! response to a light is `diffuse * cos θ * radiance`, with no `1 / π` (the path tracer uses the
//! same response, which amounts to reading the scene's intensities as `π` times a radiant intensity).
//! Emission (emissive triangles and spheres) and the environment are radiances instead: the path
//! tracer reflects them with the BSDF `diffuse / π` (see [`crate::light_sampling`]).

use englobe::{Counters, Object, Ray, Vec3, World, WorldHit};
use englobe_scene::{Light, Material, MaterialModel, Scene, SurfaceParams, TexCoords};

use crate::optics::offset_ray_origin;
use crate::ray_cone::{RayCone, footprint};
use crate::stats::{RayKind, Tally};
use crate::visibility::Visibility;

/// Shadow rays toward a point light stop this fraction short of it.
pub(crate) const SHADOW_RAY_END: f32 = 1.0 - 1e-4;

/// The parameters of a scene's materials that have no texture, by material index: they are the
/// same at every hit, so an integrator works them out once rather than at each (where the
/// roughness alone costs a division and two square roots, one waiting on the other). The default
/// knows no material's: every hit evaluates its material.
#[derive(Clone, Debug, Default)]
pub struct PlainMaterials {
    params: Vec<Option<SurfaceParams>>,
}

impl PlainMaterials {
    /// The untextured materials' parameters of `scene`.
    pub fn new(scene: &Scene) -> Self {
        let params = scene
            .materials
            .iter()
            .map(|m| m.textures.is_empty().then(|| m.evaluate_at(&scene.textures, &TexCoords::default())))
            .collect();
        PlainMaterials { params }
    }

    /// The parameters of material `index`, if it has no texture and is known here.
    #[inline]
    pub fn get(&self, index: u32) -> Option<SurfaceParams> {
        self.params.get(index as usize).copied().flatten()
    }
}

/// The shadow ray from `origin` toward `light`: to just short of a point light, to infinity
/// against a directional light's direction.
#[inline(always)]
pub fn shadow_ray(light: &Light, origin: Vec3) -> Ray {
    match *light {
        Light::Point { position, .. } => Ray::segment(origin, position - origin, 0.0, SHADOW_RAY_END),
        Light::Directional { direction, .. } => Ray::new(origin, -direction),
    }
}

/// A hit, ready for shading.
pub struct Surface<'a> {
    /// The hit point (moved back onto the surface where the shape allows).
    pub p: Vec3,
    /// The unit direction the ray travelled in.
    pub d: Vec3,
    /// Geometric normal, facing the side the ray came from.
    pub n: Vec3,
    /// Shading normal (interpolated for smooth meshes), on the same side as `n`.
    pub ns: Vec3,
    /// True if the ray arrived on the outer side of the surface (against its outward normal).
    pub entering: bool,
    /// The material.
    pub material: &'a Material,
    /// The material's parameters at this point, its textures applied.
    pub params: SurfaceParams,
}

impl<'a> Surface<'a> {
    /// The surface at `hit` of `ray`: the material's textures read at the hit's texture
    /// coordinates (each in the set it names), the shading normal bent by its normal map (in the
    /// frame of the mesh's tangents, moved into the world by an instance's transform).
    pub fn at(scene: &'a Scene, world: &World, ray: &Ray, hit: &WorldHit) -> Self {
        Self::at_over(scene, &PlainMaterials::default(), world, ray, hit, None)
    }

    /// [`Surface::at`] with the textures read over the footprint of `cone`, the ray's cone (see
    /// [`crate::ray_cone`]); `None` reads them at the hit point. The parameters of a material
    /// without textures are taken from `plain` when it has them.
    pub fn at_over(
        scene: &'a Scene,
        plain: &PlainMaterials,
        world: &World,
        ray: &Ray,
        hit: &WorldHit,
        cone: Option<RayCone>,
    ) -> Self {
        let object = &scene.objects[hit.object as usize];
        let index = object.material_of(hit.prim);
        let material = &scene.materials[index as usize];
        let p = world.hit_point(ray, hit);
        let d = ray.dir().normalize();
        let (geometric, mut shading) = world.normals(hit, p);
        let entering = d.dot(geometric) < 0.0;
        let n = if entering { geometric } else { -geometric };
        // Set 1 is interpolated only for materials that read it; each set gets its own
        // footprint, since the two map the triangle onto their images differently.
        let params = match plain.get(index) {
            Some(params) => params,
            None => {
                let mut coords = TexCoords::default();
                if !material.textures.is_empty() {
                    coords = object.tex_coords(material.textures.reads_set1(), hit.prim, hit.u, hit.v);
                    if let Some(c) = cone {
                        let width = c.width_at((p - ray.origin()).length());
                        for set in 0..2 {
                            if coords.uv[set].is_some() {
                                coords.footprint[set] = footprint(object, set as u32, hit.prim, d, width);
                            }
                        }
                    }
                }
                material.evaluate_at(&scene.textures, &coords)
            }
        };
        if let Some(bent) = params.normal_ts
            && let Some(tangent) = object.tangent(hit.prim, hit.u, hit.v)
        {
            let (t, w) = match &world.objects()[hit.object as usize] {
                Object::Instance(inst) => {
                    let m = inst.to_world();
                    (
                        m.transform_vector3(tangent.truncate()),
                        if m.matrix3.determinant() < 0.0 { -tangent.w } else { tangent.w },
                    )
                }
                _ => (tangent.truncate(), tangent.w),
            };
            // Gram-Schmidt: the tangent made perpendicular to the interpolated normal.
            let t = (t - shading * shading.dot(t)).normalize_or_zero();
            if t != Vec3::ZERO {
                let b = shading.cross(t) * w;
                shading = (t * bent.x + b * bent.y + shading * bent.z).normalize_or(shading);
            }
        }
        let ns = if shading.dot(n) < 0.0 { -shading } else { shading };
        Surface { p, d, n, ns, entering, material, params }
    }

    /// The origin of rays leaving on the side the ray came from.
    pub fn outside(&self) -> Vec3 {
        offset_ray_origin(self.p, self.n)
    }

    /// The origin of rays leaving through the surface.
    pub fn inside(&self) -> Vec3 {
        offset_ray_origin(self.p, -self.n)
    }

    /// The light `light` sends to the point, if it is in front of the surface: `(to_light,
    /// radiance, shadow_ray)`, `to_light` the unit direction to the light, `radiance` what arrives
    /// (in the units of the module's note) unless `shadow_ray`, which starts at `origin` (the
    /// point moved off the surface: [`Surface::outside`]), meets something.
    #[inline]
    pub fn light_ray(&self, light: &Light, origin: Vec3) -> Option<(Vec3, Vec3, Ray)> {
        let (to_light, radiance) = self.light_toward(light);
        if !self.faces(to_light) {
            return None; // the light is behind the surface
        }
        Some((to_light, radiance, shadow_ray(light, origin)))
    }

    /// The unit direction toward `light` and the radiance it sends to the point, whether or not
    /// the light is in front of the surface ([`Surface::faces`]). The first half of
    /// [`Surface::light_ray`], apart so that a packet's surfaces compute theirs one after the
    /// other with no branch between them, their square roots and divisions overlapping.
    #[inline(always)]
    pub fn light_toward(&self, light: &Light) -> (Vec3, Vec3) {
        match *light {
            Light::Point { position, power } => {
                // Shading uses the true point; only the shadow ray starts off the surface.
                let v = position - self.p;
                let dist2 = v.length_squared();
                (v / dist2.sqrt(), power / dist2)
            }
            Light::Directional { direction, radiance } => (-direction, radiance),
        }
    }

    /// Whether light arriving along `to_light` (see [`Surface::light_toward`]) is in front of
    /// the surface, on the side the ray came from.
    #[inline(always)]
    pub fn faces(&self, to_light: Vec3) -> bool {
        // Not `dot > 0`: a NaN product (never for a sound surface) lets the light through, as
        // it always has.
        let behind = to_light.dot(self.n) <= 0.0;
        !behind && to_light.is_finite()
    }

    /// Calls `f(to_light, radiance)` for every point or directional light in front of the
    /// surface that the point sees, one shadow ray per light (see [`Surface::light_ray`]).
    pub fn for_each_light<C: Counters>(
        &self,
        scene: &Scene,
        vis: &Visibility,
        tally: &mut Tally<C>,
        mut f: impl FnMut(Vec3, Vec3),
    ) {
        let origin = self.outside();
        for light in &scene.lights {
            let Some((to_light, radiance, shadow_ray)) = self.light_ray(light, origin) else { continue };
            tally.rays[RayKind::Shadow as usize] += 1;
            if vis.any_hit(&shadow_ray, &mut tally.work[RayKind::Shadow as usize]) {
                continue;
            }
            f(to_light, radiance);
        }
    }

    /// What one light that the point sees adds to [`Surface::direct_light`]'s `(diffuse,
    /// highlight)`. The Blinn-Phong highlight belongs to the classic model; a metallic-roughness
    /// material reaches Whitted's integrator as its diffuse base colour (zero highlight).
    #[inline]
    pub fn light_response(&self, to_light: Vec3, radiance: Vec3) -> (Vec3, Vec3) {
        let m = &self.params;
        let diffuse = m.base_color * self.ns.dot(to_light).max(0.0) * radiance;
        if m.specular == Vec3::ZERO || self.material.model != MaterialModel::Classic {
            return (diffuse, Vec3::ZERO);
        }
        let half = (to_light - self.d).normalize_or_zero();
        (diffuse, m.specular * self.ns.dot(half).max(0.0).powf(self.material.shininess) * radiance)
    }

    /// The diffuse and highlight light arriving from every light that the point sees, one
    /// shadow ray per light in front of the surface. Returns `(diffuse, highlight)`, the first
    /// to be weighted by the surface's diffuse share.
    pub fn direct_light<C: Counters>(&self, scene: &Scene, vis: &Visibility, tally: &mut Tally<C>) -> (Vec3, Vec3) {
        let (mut diffuse, mut highlight) = (Vec3::ZERO, Vec3::ZERO);
        self.for_each_light(scene, vis, tally, |to_light, radiance| {
            let (d, h) = self.light_response(to_light, radiance);
            diffuse += d;
            highlight += h;
        });
        (diffuse, highlight)
    }
}

#[cfg(test)]
mod tests {
    use englobe::Vec2;
    use englobe_scene::{AlphaMode, MaterialModel, TextureRef};

    use super::*;

    /// What the table gives is what every hit would evaluate, for every model and alpha mode,
    /// wherever the hit; a material with a texture, or one the table does not know, is left to
    /// each hit.
    #[test]
    fn plain_materials_are_what_each_hit_would_evaluate() {
        let text = r#"
            [image]
            width = 8
            height = 8
            [camera]
            position = [0.0, 0.0, -3.0]
            look_at = [0.0, 0.0, 0.0]
            fov = 40
            [materials.clay]
            diffuse = [0.8, 0.6, 0.5]
            specular = [0.2, 0.2, 0.2]
            shininess = 30
            [[sphere]]
            center = [0.0, 0.0, 0.0]
            radius = 1.0
            material = "clay"
        "#;
        let mut scene = englobe_scene::parse_scene(text, "clay.toml".as_ref()).unwrap();
        let mut metal = scene.materials[0].clone();
        metal.model = MaterialModel::MetallicRoughness { metallic: 0.3, roughness: 0.6, transmission: 0.1 };
        metal.alpha.mode = AlphaMode::Blend;
        metal.alpha.factor = 0.4;
        let mut textured = scene.materials[0].clone();
        textured.textures.base_color = Some(TextureRef::new(0));
        scene.materials.extend([metal, textured]);
        let plain = PlainMaterials::new(&scene);
        let last = scene.materials.len() - 1;
        for (i, m) in scene.materials.iter().enumerate() {
            let at_hit = m.evaluate_at(&scene.textures, &TexCoords::one(Some(Vec2::new(0.3, 0.7)), None));
            let expected = (i != last).then_some(at_hit);
            assert_eq!(plain.get(i as u32), expected, "material {i}");
        }
        assert_eq!(plain.get(scene.materials.len() as u32), None);
        assert_eq!(PlainMaterials::default().get(0), None);
    }
}
