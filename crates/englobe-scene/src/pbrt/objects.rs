//! Object instancing: `ObjectBegin "name"` ... `ObjectEnd` defines an object from the shapes
//! between them (each placed by the transformation matrix of its own time), and
//! `ObjectInstance "name"` places the object again under the current matrix. englobe keeps one copy
//! of each mesh and places it as an instance ([`englobe::Instance`]): one bottom-level structure
//! per mesh, however many times it is placed. Area lights inside objects do not emit (pbrt-v4
//! refuses them too).

use englobe::{Affine3A, Instance, Object, Vec3};

use super::builder::{Builder, Part, Placed, Scope};
use super::source::{Place, Res, fail};

/// Most objects placed by `ObjectInstance`, all objects together.
pub(super) const MAX_INSTANCES: usize = 1 << 24;

impl Builder {
    /// `ObjectBegin "name"`: opens an attribute scope and collects the shapes that follow.
    pub fn object_begin(&mut self, at: Place, name: &str) -> Res<()> {
        self.require_world(at, "ObjectBegin")?;
        if let Some((open, opened, _)) = &self.defining {
            return fail(
                at,
                format!("ObjectBegin inside the definition of \"{open}\" (opened at {})", self.sources.show(*opened)),
            );
        }
        if self.objects.contains_key(name) {
            return fail(at, format!("the object \"{name}\" is defined twice"));
        }
        self.begin(at, Scope::Attribute)?;
        self.defining = Some((name.to_owned(), at, Vec::new()));
        Ok(())
    }

    /// `ObjectEnd`.
    pub fn object_end(&mut self, at: Place) -> Res<()> {
        let Some((name, _, parts)) = self.defining.take() else {
            return fail(at, "ObjectEnd without a matching ObjectBegin");
        };
        self.objects.insert(name, parts);
        self.end(at, Scope::Attribute)
    }

    /// `ObjectInstance "name"`: places every part of the object under the current matrix.
    pub fn object_instance(&mut self, at: Place, name: &str) -> Res<()> {
        self.require_world(at, "ObjectInstance")?;
        if self.defining.is_some() {
            return fail(at, "ObjectInstance inside an object definition is not allowed (as in pbrt)");
        }
        let Some(parts) = self.objects.get(name).cloned() else {
            return fail(at, format!("ObjectInstance \"{name}\": no object of that name is defined before this point"));
        };
        if self.placed.len() + parts.len() > MAX_INSTANCES {
            return fail(at, format!("more than {MAX_INSTANCES} objects placed"));
        }
        let what = format!("ObjectInstance \"{name}\"");
        let m = self.gs.ctm;
        let affine = Affine3A::from_mat4(m.as_mat4());
        for part in parts {
            match part {
                Part::Mesh(mesh, material) => match Instance::new(mesh, affine) {
                    Ok(instance) => {
                        self.placed.push(Placed { object: Object::Instance(instance), material, emission: Vec3::ZERO })
                    }
                    Err(e) => {
                        self.report.skipped(at, "instance transform", || {
                            format!("{what}: this instance cannot be placed ({e}): not drawn")
                        })?;
                    }
                },
                Part::Sphere(sphere, material) => {
                    if let Some(s) = self.placed_sphere(at, sphere, &m, &what)? {
                        self.placed.push(Placed { object: s.into(), material, emission: Vec3::ZERO });
                    }
                }
            }
        }
        Ok(())
    }
}
