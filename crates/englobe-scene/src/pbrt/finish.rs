//! The end of a pbrt scene: named materials resolved, emissive shapes given a material of their
//! own (the shape's material plus the area light's radiance), the camera and image settings read,
//! and the report turned into the scene's warnings.

use std::collections::HashMap;

use englobe::{Aabb, Bounded, Object};

use super::builder::Builder;
use super::source::{Res, fail};
use crate::model::{Material, MaterialId, Scene, SceneObject};

impl Builder {
    /// The scene.
    pub fn finish(&mut self) -> Res<Scene> {
        if let Some((name, at, _)) = &self.defining {
            return fail(*at, format!("ObjectBegin \"{name}\" is never closed by ObjectEnd"));
        }
        self.close_all()?;
        let mut emissive: HashMap<(MaterialId, [u32; 3]), MaterialId> = HashMap::new();
        let mut objects = Vec::with_capacity(self.placed.len());
        let mut bounds = Aabb::EMPTY;
        for p in std::mem::take(&mut self.placed) {
            let mut id = self.resolve(&p.material)?;
            if self.invisible[id as usize] {
                continue;
            }
            if p.emission != englobe::Vec3::ZERO {
                let key = (id, p.emission.to_array().map(f32::to_bits));
                id = match emissive.get(&key) {
                    Some(&e) => e,
                    None => {
                        let base = &self.materials[id as usize];
                        let material = Material { emission: p.emission, ..base.clone() };
                        let name = format!("{} + area light {}", self.material_names[id as usize], p.emission);
                        let e = self.add_material(name, material, false);
                        emissive.insert(key, e);
                        e
                    }
                };
            }
            bounds = bounds.union(&match &p.object {
                Object::Shape(s) if s.is_bounded() => s.bounds(),
                Object::Shape(_) => Aabb::EMPTY,
                Object::Mesh(m) => m.bounds(),
                Object::Instance(i) => i.bounds(),
            });
            objects.push(SceneObject::new(p.object, id));
        }
        let (image, camera) = self.image_and_camera(bounds)?;
        let mut warnings = self.report.warnings(&self.sources);
        warnings.append(&mut self.mesh_warnings);
        Ok(Scene {
            image,
            camera,
            lights: std::mem::take(&mut self.lights),
            materials: std::mem::take(&mut self.materials),
            material_names: std::mem::take(&mut self.material_names),
            textures: Vec::new(),
            objects,
            environment: None,
            warnings,
        })
    }
}
