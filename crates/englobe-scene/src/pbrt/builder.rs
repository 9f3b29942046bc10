//! The scene a pbrt file describes, built directive by directive: the graphics state (current
//! transformation matrix, material, area light, orientation) with its attribute stack, the named
//! coordinate systems, materials and textures, and what has been placed so far. pbrt-v4's
//! `BasicSceneBuilder` (`scene.cpp`) is the model; the other files of this folder add the
//! directives of one kind each (options, materials, shapes, lights, instances).

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

use englobe::{Object, TriangleMesh, Vec3};
use glam::DMat4;

use super::report::Report;
use super::source::{Place, Res, Sources, fail};
use super::values::{Texture, default_material};
use crate::model::{Light, Material, MaterialId};

/// Which of a `TransformTimes` pair the transformation directives change.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Active {
    /// Both (the default).
    All,
    /// The start only: the transform englobe renders.
    Start,
    /// The end only: ignored, as englobe renders the start of the shutter interval.
    End,
}

/// A shape's material: resolved, or a name looked up when the file is done (pbrt-v4 lets
/// `NamedMaterial` come before `MakeNamedMaterial`).
#[derive(Clone, Debug, PartialEq)]
pub(super) enum MatRef {
    Id(MaterialId),
    Named(String, Place),
}

/// The `AreaLightSource` in effect.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct AreaLight {
    /// Emitted radiance (RGB times scale).
    pub radiance: Vec3,
    /// pbrt's `power`: when given, the radiance is scaled so that each shape emits this power.
    pub power: Option<f64>,
    /// pbrt's `twosided`: emits from both sides (englobe emits from the front only, reported).
    pub two_sided: bool,
    pub at: Place,
}

/// pbrt's graphics state: what `AttributeBegin` saves and `AttributeEnd` restores.
#[derive(Clone, Debug)]
pub(super) struct GraphicsState {
    /// World from object.
    pub ctm: DMat4,
    pub reverse_orientation: bool,
    pub material: MatRef,
    pub area_light: Option<AreaLight>,
    pub active: Active,
}

/// What an attribute-stack entry restores.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Scope {
    /// `AttributeBegin`: the whole graphics state.
    Attribute,
    /// pbrt-v3's `TransformBegin`: the transformation matrix only.
    Transform,
    /// An `Import`ed file: the whole state, restored when the file ends.
    Import,
}

/// A directive kept until the file is done (the camera and film options need each other).
#[derive(Clone, Debug)]
pub(super) struct Decl {
    pub kind: String,
    pub params: super::params::Params,
    pub at: Place,
}

/// A shape placed in the world, its material and emission resolved when the file is done.
pub(super) struct Placed {
    pub object: Object,
    pub material: MatRef,
    pub emission: Vec3,
}

/// A mesh or sphere of an object definition (`ObjectBegin`), in the object's space.
#[derive(Clone)]
pub(super) enum Part {
    Mesh(Arc<TriangleMesh>, MatRef),
    Sphere(englobe::Sphere, MatRef),
}

/// The scene under construction.
pub(super) struct Builder {
    pub sources: Sources,
    pub report: Report,
    /// The folder relative paths are resolved against first: the main file's (pbrt's rule).
    pub search_dir: PathBuf,
    pub gs: GraphicsState,
    stack: Vec<(GraphicsState, Scope, Place)>,
    pub named_coordinates: HashMap<String, DMat4>,
    pub in_world: bool,
    pub camera: Option<(Decl, DMat4)>,
    pub film: Option<Decl>,
    pub sampler: Option<Decl>,
    pub integrator: Option<Decl>,
    pub filter: Option<Decl>,
    /// `Option "integer seed"`.
    pub option_seed: Option<u64>,
    pub named_materials: HashMap<String, MaterialId>,
    pub textures: HashMap<String, Texture>,
    pub materials: Vec<Material>,
    pub material_names: Vec<String>,
    /// Materials that pbrt's `interface` type makes (boundaries of media only): their shapes are
    /// not rendered.
    pub invisible: Vec<bool>,
    pub placed: Vec<Placed>,
    pub lights: Vec<Light>,
    pub background: Vec3,
    /// Mesh files read, by canonical path, in their own space.
    pub mesh_files: HashMap<PathBuf, Arc<TriangleMesh>>,
    /// The object being defined (`ObjectBegin`) and its parts.
    pub defining: Option<(String, Place, Vec<Part>)>,
    pub objects: HashMap<String, Vec<Part>>,
    /// Warnings of the mesh files, prefixed by their name.
    pub mesh_warnings: Vec<String>,
}

/// Deepest attribute stack (nested `AttributeBegin`) accepted.
pub(super) const MAX_ATTRIBUTE_DEPTH: usize = 1 << 12;

impl Builder {
    pub fn new(sources: Sources, strict: bool, search_dir: PathBuf) -> Self {
        Builder {
            sources,
            report: Report::new(strict),
            search_dir,
            gs: GraphicsState {
                ctm: DMat4::IDENTITY,
                reverse_orientation: false,
                material: MatRef::Id(0),
                area_light: None,
                active: Active::All,
            },
            stack: Vec::new(),
            named_coordinates: HashMap::new(),
            in_world: false,
            camera: None,
            film: None,
            sampler: None,
            integrator: None,
            filter: None,
            option_seed: None,
            named_materials: HashMap::new(),
            textures: HashMap::new(),
            materials: vec![default_material()],
            material_names: vec![crate::model::DEFAULT_MATERIAL.to_owned()],
            invisible: vec![false],
            placed: Vec::new(),
            lights: Vec::new(),
            background: Vec3::ZERO,
            mesh_files: HashMap::new(),
            defining: None,
            objects: HashMap::new(),
            mesh_warnings: Vec::new(),
        }
    }

    /// Sets the transformation matrix, unless `ActiveTransform EndTime` asks for the end of the
    /// shutter interval only (reported: englobe renders the start).
    pub fn set_ctm(&mut self, at: Place, m: DMat4) -> Res<()> {
        if self.gs.active == Active::End {
            return self.report.approximated(at, "ActiveTransform EndTime", || {
                "transforms at the end of the shutter interval (motion blur): englobe renders the start".into()
            });
        }
        if !m.is_finite() {
            return fail(at, "the transformation matrix is no longer finite");
        }
        self.gs.ctm = m;
        Ok(())
    }

    pub fn begin(&mut self, at: Place, scope: Scope) -> Res<()> {
        if self.stack.len() >= MAX_ATTRIBUTE_DEPTH {
            return fail(at, format!("more than {MAX_ATTRIBUTE_DEPTH} nested AttributeBegin"));
        }
        self.stack.push((self.gs.clone(), scope, at));
        Ok(())
    }

    /// Ends the innermost scope, which must be of kind `scope`.
    pub fn end(&mut self, at: Place, scope: Scope) -> Res<()> {
        let (name, begin) = match scope {
            Scope::Attribute => ("AttributeEnd", "AttributeBegin"),
            Scope::Transform => ("TransformEnd", "TransformBegin"),
            Scope::Import => ("the end of an imported file", "Import"),
        };
        match self.stack.last() {
            Some((_, s, _)) if *s == scope => {}
            Some((_, Scope::Import, _)) | None => return fail(at, format!("{name} without a matching {begin}")),
            Some((_, _, opened)) => {
                let opened = self.sources.show(*opened);
                return fail(at, format!("{name} does not match the scope opened at {opened}"));
            }
        }
        let (saved, _, _) = self.stack.pop().expect("checked above");
        match scope {
            Scope::Transform => (self.gs.ctm, self.gs.active) = (saved.ctm, saved.active),
            _ => self.gs = saved,
        }
        Ok(())
    }

    /// Closes an imported file's scope, closing (with a warning) what it left open.
    pub fn end_import(&mut self, at: Place) -> Res<()> {
        while let Some((_, scope, opened)) = self.stack.last().cloned() {
            if scope == Scope::Import {
                break;
            }
            self.report.ignored(opened, "unclosed in import", || {
                "this scope is still open at the end of the imported file: closed there".into()
            })?;
            self.end(at, scope)?;
        }
        self.end(at, Scope::Import)
    }

    /// Reports the scopes still open when the scene ends (pbrt warns about them too).
    pub fn close_all(&mut self) -> Res<()> {
        while let Some((_, _, opened)) = self.stack.pop() {
            self.report.ignored(opened, "unclosed at end", || "this scope is never closed".into())?;
        }
        Ok(())
    }

    /// Refuses a world-block directive before `WorldBegin` (as pbrt does).
    pub fn require_world(&self, at: Place, what: &str) -> Res<()> {
        if !self.in_world {
            return fail(at, format!("{what} is allowed only after WorldBegin"));
        }
        Ok(())
    }

    /// Refuses an option directive after `WorldBegin` (as pbrt does).
    pub fn require_options(&self, at: Place, what: &str) -> Res<()> {
        if self.in_world {
            return fail(at, format!("{what} is allowed only before WorldBegin"));
        }
        Ok(())
    }

    pub fn world_begin(&mut self, at: Place) -> Res<()> {
        if self.in_world {
            return fail(at, "WorldBegin appears twice");
        }
        self.in_world = true;
        self.gs.ctm = DMat4::IDENTITY;
        self.named_coordinates.insert("world".into(), DMat4::IDENTITY);
        Ok(())
    }

    /// Adds a material under `name` (made unique by a suffix if taken); returns its id.
    pub fn add_material(&mut self, name: String, material: Material, invisible: bool) -> MaterialId {
        let mut unique = name.clone();
        let mut k = 2;
        while self.material_names.contains(&unique) {
            unique = format!("{name} #{k}");
            k += 1;
        }
        self.materials.push(material);
        self.material_names.push(unique);
        self.invisible.push(invisible);
        (self.materials.len() - 1) as MaterialId
    }

    /// The material a reference names; an unknown name is an error at the `NamedMaterial`.
    pub fn resolve(&self, m: &MatRef) -> Res<MaterialId> {
        match m {
            MatRef::Id(id) => Ok(*id),
            MatRef::Named(name, at) => match self.named_materials.get(name) {
                Some(&id) => Ok(id),
                None => {
                    let mut known: Vec<&str> = self.named_materials.keys().map(String::as_str).collect();
                    known.sort_unstable();
                    let known = if known.is_empty() { "none".to_owned() } else { known.join(", ") };
                    fail(
                        *at,
                        format!("NamedMaterial \"{name}\" is never defined by MakeNamedMaterial (defined: {known})"),
                    )
                }
            },
        }
    }

    /// The folders a relative path named at `at` is looked for in: the main file's (pbrt's rule),
    /// then the naming file's.
    pub fn candidates(&self, at: Place, name: &str) -> Vec<PathBuf> {
        let path = std::path::Path::new(name);
        if path.is_absolute() {
            return vec![path.to_owned()];
        }
        let mut out = vec![self.search_dir.join(path)];
        if let Some(dir) = self.sources.get(at.file).path.parent() {
            let beside = dir.join(path);
            if beside != out[0] {
                out.push(beside);
            }
        }
        out
    }

    /// Reports the parameters of a directive that nothing read; `kind` groups them ("Shape
    /// sphere") so that each is reported once, `what` names the directive in the message.
    pub fn report_unused(&mut self, params: &super::params::Params, kind: &str, what: &str) -> Res<()> {
        for p in params.unused() {
            let shown = p.shown();
            self.report.skipped(p.at, &format!("unused {kind} {shown}"), || {
                format!("{what}: parameter {shown} is not supported: ignored")
            })?;
        }
        Ok(())
    }
}
