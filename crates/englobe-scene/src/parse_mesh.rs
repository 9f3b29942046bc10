//! `[[mesh]]` entries: mesh files placed in the scene once (the transform is baked into a copy of
//! the vertices) or many times (instances sharing one mesh and one bottom-level structure).
//!
//! Transforms are `translate`, `rotate` (degrees about the fixed x, then y, then z axes) and
//! `scale`, applied as `translate * rotate_z * rotate_y * rotate_x * scale`, or a row-major 4x4
//! `matrix`. An instance's own transform is applied after the entry's. A file named by several
//! entries is read once.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

use englobe::{Affine3A, Instance, Object, TriangleMesh, Vec3};
use glam::{EulerRot, Quat, Vec4};
use toml::Spanned;

use crate::error::{Located, SceneError};
use crate::format::{GridDef, MeshDef, TransformDef};
use crate::mesh::{MeshOptions, NO_MATERIAL, bake_transform, load_mesh_file_with, transform_tangents};
use crate::model::{MaterialId, Scene, SceneObject};
use crate::numbers::{Matrix, Point, Scale};
use crate::parse::Converter;

/// Most instances one `[[mesh]]` entry may place.
pub const MAX_MESH_INSTANCES: u64 = 1 << 24;

/// A mesh file read for this scene, with its materials already added to the scene's.
struct Cached {
    mesh: Arc<TriangleMesh>,
    /// Scene material of each triangle, when the file gives materials.
    triangle_materials: Option<Arc<[MaterialId]>>,
    /// Per-vertex tangents, when the file gives them or a normal map needs them.
    tangents: Option<Arc<[Vec4]>>,
}

impl Converter<'_> {
    /// Loads every `[[mesh]]` entry into `scene`.
    pub(crate) fn meshes(&self, defs: Vec<Spanned<MeshDef>>, scene: &mut Scene) -> Result<(), SceneError> {
        let scene_materials = scene.material_names.len();
        // A file is read once per smoothing angle and need of tangents (what is generated differs).
        let mut cache: HashMap<(PathBuf, u32, bool), Cached> = HashMap::new();
        for def in defs {
            let entry_span = def.span();
            let d = def.into_inner();
            let override_material = match &d.material {
                Some(name) => Some(
                    scene.material_names[..scene_materials]
                        .iter()
                        .position(|n| n == name.get_ref())
                        .map(|i| i as MaterialId)
                        .ok_or_else(|| {
                            let known = scene.material_names[..scene_materials].join(", ");
                            self.err(
                                name.span(),
                                format!("unknown material `{}`; the scene defines: {known}", name.get_ref()),
                            )
                        })?,
                ),
                None => None,
            };
            let placement = self.transform(
                &TransformDef { translate: d.translate, rotate: d.rotate, scale: d.scale, matrix: d.matrix },
                entry_span.clone(),
            )?;

            let file = self.dir.join(d.path.get_ref());
            let want_tangents =
                override_material.is_some_and(|m| scene.materials[m as usize].textures.normal.is_some());
            let options = MeshOptions {
                smooth_angle: d.smooth_angle.as_ref().map_or(MeshOptions::default().smooth_angle, |a| a.get_ref().0),
                want_tangents,
            };
            if let Some(a) = &d.smooth_angle {
                if !(0.0..=180.0).contains(&a.get_ref().0) {
                    return Err(self
                        .err(a.span(), format!("a smoothing angle of {} degrees: expected 0 to 180", a.get_ref().0)));
                }
            }
            let key = (
                std::fs::canonicalize(&file).unwrap_or_else(|_| file.clone()),
                options.smooth_angle.to_bits(),
                want_tangents,
            );
            if !cache.contains_key(&key) {
                self.observer.mesh_started(&file);
                let start = std::time::Instant::now();
                let loaded = load_mesh_file_with(&file, &options).map_err(|mesh| SceneError::Mesh {
                    located: located(
                        self,
                        d.path.span(),
                        format!("cannot load the mesh `{}`: {mesh}", d.path.get_ref()),
                    ),
                    mesh: Box::new(mesh),
                })?;
                self.observer.mesh_loaded(&file, loaded.mesh.len(), start.elapsed());
                scene.warnings.extend(loaded.warnings.iter().map(|w| format!("{}: {w}", file.display())));
                let stem = file.file_name().map_or(String::new(), |n| n.to_string_lossy().into_owned());
                let first = scene.materials.len() as MaterialId;
                let first_texture = scene.textures.len() as crate::TextureId;
                scene.textures.extend(loaded.textures.iter().cloned());
                for (name, material) in &loaded.materials {
                    let mut material = material.clone();
                    material.textures = material.textures.shifted(first_texture);
                    scene.materials.push(material);
                    scene.material_names.push(format!("{stem}:{name}"));
                }
                let triangle_materials = loaded.triangle_materials.as_ref().map(|ids| {
                    ids.iter().map(|&m| if m == NO_MATERIAL { 0 } else { first + m }).collect::<Arc<[MaterialId]>>()
                });
                let tangents = loaded.tangents.map(Arc::from);
                cache.insert(key.clone(), Cached { mesh: Arc::new(loaded.mesh), triangle_materials, tangents });
            }
            let cached = &cache[&key];
            let (material, triangle_materials) = match override_material {
                Some(m) => (m, None),
                None => (0, cached.triangle_materials.clone()),
            };
            let mut push = |object: Object, tangents: Option<Arc<[Vec4]>>| {
                scene.objects.push(SceneObject {
                    object,
                    material,
                    triangle_materials: triangle_materials.clone(),
                    tangents,
                })
            };

            let instances = self.instances(&d.instances, &d.grid, entry_span.clone())?;
            match instances {
                None => {
                    let (mesh, tangents) = if placement == Affine3A::IDENTITY {
                        (cached.mesh.clone(), cached.tangents.clone())
                    } else {
                        let mesh =
                            bake_transform(&cached.mesh, &placement).map_err(|e| self.err(entry_span.clone(), e))?;
                        (Arc::new(mesh), cached.tangents.as_ref().map(|t| Arc::from(transform_tangents(t, &placement))))
                    };
                    push(Object::Mesh(mesh), tangents);
                }
                Some(list) => {
                    for (transform, span) in list {
                        let instance = Instance::new(cached.mesh.clone(), transform * placement)
                            .map_err(|e| self.err(span, format!("this instance cannot be placed: {e}")))?;
                        push(Object::Instance(instance), cached.tangents.clone());
                    }
                }
            }
        }
        Ok(())
    }

    /// The placements of an entry's instances, with the span to blame for each, or `None` when the
    /// entry places the mesh once.
    #[allow(clippy::type_complexity)]
    fn instances(
        &self,
        list: &Option<Vec<Spanned<TransformDef>>>,
        grid: &Option<Spanned<GridDef>>,
        entry: std::ops::Range<usize>,
    ) -> Result<Option<Vec<(Affine3A, std::ops::Range<usize>)>>, SceneError> {
        match (list, grid) {
            (None, None) => Ok(None),
            (Some(_), Some(g)) => Err(self.err(g.span(), "a mesh takes `instances` or `grid`, not both")),
            (Some(list), None) => {
                if list.len() as u64 > MAX_MESH_INSTANCES {
                    return Err(self.err(entry, format!("more than {MAX_MESH_INSTANCES} instances")));
                }
                list.iter()
                    .map(|t| Ok((self.transform(t.get_ref(), t.span())?, t.span())))
                    .collect::<Result<_, _>>()
                    .map(Some)
            }
            (None, Some(g)) => {
                let span = g.span();
                let g = g.get_ref();
                let total: u64 = g.counts.iter().map(|&c| c as u64).product();
                if total > MAX_MESH_INSTANCES {
                    return Err(self
                        .err(span, format!("a grid of {total} instances is over the limit of {MAX_MESH_INSTANCES}")));
                }
                let origin = g.origin.map_or(Vec3::ZERO, |o| o.0);
                let step = g.rotate_step.map_or(Vec3::ZERO, |r| r.0);
                let mut out = Vec::with_capacity(total as usize);
                for k in 0..g.counts[2] {
                    for j in 0..g.counts[1] {
                        for i in 0..g.counts[0] {
                            let n = out.len() as f32;
                            let at = origin + g.spacing.0 * Vec3::new(i as f32, j as f32, k as f32);
                            if !at.is_finite() {
                                return Err(self.err(span, "the grid reaches beyond what 32-bit floats can hold"));
                            }
                            out.push((Affine3A::from_rotation_translation(rotation(step * n), at), span.clone()));
                        }
                    }
                }
                Ok(Some(out))
            }
        }
    }

    /// The affine transform of `t`; `span` is blamed for conflicts.
    fn transform(&self, t: &TransformDef, span: std::ops::Range<usize>) -> Result<Affine3A, SceneError> {
        transform(t).map_err(|e| self.err(span, e))
    }
}

/// `translate * rotate_z * rotate_y * rotate_x * scale`, or the matrix.
fn transform(t: &TransformDef) -> Result<Affine3A, String> {
    if let Some(Matrix(m)) = t.matrix {
        if t.translate.is_some() || t.rotate.is_some() || t.scale.is_some() {
            return Err("`matrix` cannot be combined with `translate`, `rotate` or `scale`".into());
        }
        if m.matrix3.determinant() == 0.0 {
            return Err("the matrix is singular (its 3x3 part has determinant 0)".into());
        }
        return Ok(m);
    }
    let scale = t.scale.map_or(Vec3::ONE, |Scale(s)| s);
    let rotate = t.rotate.map_or(Vec3::ZERO, |Point(r)| r);
    let translate = t.translate.map_or(Vec3::ZERO, |Point(p)| p);
    Ok(Affine3A::from_scale_rotation_translation(scale, rotation(rotate), translate))
}

/// Rotation by `degrees` about the fixed x, then y, then z axes.
fn rotation(degrees: Vec3) -> Quat {
    let r = degrees * (std::f32::consts::PI / 180.0);
    Quat::from_euler(EulerRot::ZYX, r.z, r.y, r.x)
}

fn located(c: &Converter, span: std::ops::Range<usize>, message: String) -> Located {
    c.locate(span, message)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotations_are_about_x_then_y_then_z() {
        let q = rotation(Vec3::new(90.0, 90.0, 0.0));
        // +y turns to +z about x, then +z turns to +x about y.
        assert!((q * Vec3::Y - Vec3::X).length() < 1e-6, "{}", q * Vec3::Y);
        let t = transform(&TransformDef {
            translate: Some(Point(Vec3::new(1.0, 2.0, 3.0))),
            rotate: Some(Point(Vec3::new(0.0, 0.0, 90.0))),
            scale: Some(Scale(Vec3::new(2.0, 1.0, 1.0))),
            matrix: None,
        })
        .unwrap();
        // Scale x by 2, turn x to y, then move.
        assert!((t.transform_point3(Vec3::X) - Vec3::new(1.0, 4.0, 3.0)).length() < 1e-6);
    }
}
