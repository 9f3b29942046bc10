//! From scene text to a validated [`Scene`]: parse the TOML into [`crate::format`], then check
//! what a single value cannot say on its own (the camera, cross references, limits) and build the
//! objects.

use std::ops::Range;
use std::path::Path;

use englobe::{AaBox, Object, Plane, Sphere, Triangle, Vec2, Vec3};
use serde::Deserialize;
use toml::Spanned;
use toml::de::DeTable;

use crate::error::{Located, SceneError};
use crate::format::{CameraDef, FilterRadius, ImageDef, ProjectionKind, SceneFile};
use crate::load_observer::{LoadObserver, Unobserved};
use crate::model::{Camera, ImageSettings, Light, MaterialId, Projection, Scene, SceneObject};
use crate::overrides::{Override, Placed};
use crate::pixel_filter::{MAX_FILTER_RADIUS, PixelFilter};

pub use crate::model::DEFAULT_MATERIAL;
/// Most spheres one `[[sphere_grid]]` may generate.
pub const MAX_GRID_SPHERES: u64 = 1 << 24;
/// Largest scene file read.
pub const MAX_SCENE_BYTES: u64 = 64 << 20;

/// Reads and validates the scene file at `path`.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    load_scene_with(path, &[])
}

/// Reads the scene file at `path`, applies `overrides` (see [`crate::overrides`]) and validates
/// the result.
///
/// A `.pbrt` file is read by [`crate::pbrt::load`] (not strict); overrides do not apply to it, so
/// any is refused.
pub fn load_scene_with(path: &Path, overrides: &[Override]) -> Result<Scene, SceneError> {
    load_scene_observed(path, overrides, &Unobserved)
}

/// [`load_scene_with`], telling `observer` when each mesh file starts and ends loading (not for
/// `.pbrt` files, whose shapes are not mesh files).
pub fn load_scene_observed(
    path: &Path,
    overrides: &[Override],
    observer: &dyn LoadObserver,
) -> Result<Scene, SceneError> {
    if crate::pbrt::is_pbrt_path(path) {
        crate::pbrt::refuse_overrides(overrides)?;
        return crate::pbrt::load(path, false);
    }
    let meta = std::fs::metadata(path).map_err(|e| SceneError::io(path, e))?;
    if meta.is_dir() {
        return Err(SceneError::io(path, std::io::Error::other("is a directory, expected a scene file")));
    }
    let too_large = |bytes: String| {
        SceneError::io(path, std::io::Error::other(format!("{bytes} is larger than the {MAX_SCENE_BYTES}-byte limit")))
    };
    if meta.len() > MAX_SCENE_BYTES {
        return Err(too_large(format!("{} bytes", meta.len())));
    }
    // A device or a pipe has no size beforehand: the limit holds while reading.
    let file = std::fs::File::open(path).map_err(|e| SceneError::io(path, e))?;
    let bytes = crate::mesh::read_at_most(file, meta.len() as usize, MAX_SCENE_BYTES + 1)
        .map_err(|e| SceneError::io(path, e))?;
    if bytes.len() as u64 > MAX_SCENE_BYTES {
        return Err(too_large("the file".into()));
    }
    let text = String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        SceneError::at(&path.display().to_string(), "", None, format!("byte {at}: the file is not valid UTF-8"))
    })?;
    parse_scene_observed(&text, path, overrides, observer)
}

/// Validates scene `text`; `file` names it in errors.
pub fn parse_scene(text: &str, file: &Path) -> Result<Scene, SceneError> {
    parse_scene_with(text, file, &[])
}

/// Applies `overrides` to scene `text` and validates the result; `file` names the text in errors,
/// and an error in an overridden value names the override.
pub fn parse_scene_with(text: &str, file: &Path, overrides: &[Override]) -> Result<Scene, SceneError> {
    parse_scene_observed(text, file, overrides, &Unobserved)
}

/// [`parse_scene_with`], telling `observer` when each mesh file starts and ends loading.
pub fn parse_scene_observed(
    text: &str,
    file: &Path,
    overrides: &[Override],
    observer: &dyn LoadObserver,
) -> Result<Scene, SceneError> {
    let name = file.display().to_string();
    let placed = Placed::new(text.len(), overrides);
    let invalid = |span: Option<Range<usize>>, message: &str| {
        SceneError::Invalid(placed.locate(&name, text, span, message.to_owned()))
    };
    let mut root = DeTable::parse(text).map_err(|e| invalid(e.span(), e.message()))?;
    crate::overrides::apply(root.get_mut(), overrides, &placed, &name, text).map_err(SceneError::Invalid)?;
    let def = SceneFile::deserialize(toml::de::Deserializer::from(root)).map_err(|e| invalid(e.span(), e.message()))?;
    Converter { file: &name, text, dir: file.parent().unwrap_or(Path::new("")), placed: &placed, observer }.scene(def)
}

pub(crate) struct Converter<'a> {
    pub(crate) file: &'a str,
    pub(crate) text: &'a str,
    /// The scene file's folder, against which mesh paths are resolved.
    pub(crate) dir: &'a Path,
    /// Where the command line's overrides stand, for errors in their values.
    pub(crate) placed: &'a Placed,
    /// Told of each mesh file as it loads.
    pub(crate) observer: &'a dyn LoadObserver,
}

impl Converter<'_> {
    pub(crate) fn err(&self, span: Range<usize>, message: impl Into<String>) -> SceneError {
        SceneError::Invalid(self.locate(span, message))
    }

    pub(crate) fn locate(&self, span: Range<usize>, message: impl Into<String>) -> Located {
        self.placed.locate(self.file, self.text, Some(span), message.into())
    }

    fn scene(&self, def: SceneFile) -> Result<Scene, SceneError> {
        let image = self.image(def.image)?;
        let camera = self.camera(def.camera)?;
        let mut warnings = Vec::new();
        let (materials, material_names, textures) = self.materials(def.materials, &mut warnings)?;
        let lookup = |m: &Option<Spanned<String>>| -> Result<MaterialId, SceneError> {
            let Some(m) = m else { return Ok(0) };
            material_names.iter().position(|n| n == m.get_ref()).map(|i| i as MaterialId).ok_or_else(|| {
                let known = material_names.join(", ");
                self.err(m.span(), format!("unknown material `{}`; the scene defines: {known}", m.get_ref()))
            })
        };

        let mut lights = Vec::new();
        for l in def.point_light {
            lights.push(Light::Point { position: l.position.0, power: light_power(l.color, l.intensity) });
        }
        for l in def.directional_light {
            let Some(direction) = l.direction.get_ref().0.try_normalize() else {
                return Err(self.err(l.direction.span(), "a directional light needs a non-zero direction"));
            };
            lights.push(Light::Directional { direction, radiance: light_power(l.color, l.intensity) });
        }

        let mut objects = Vec::new();
        let mut push = |object: Object, material| objects.push(SceneObject::new(object, material));
        for s in def.sphere {
            push(Sphere::new(s.center.0, s.radius.0).into(), lookup(&s.material)?);
        }
        for grid in def.sphere_grid {
            let span = grid.span();
            let g = grid.into_inner();
            let total = g.counts.iter().map(|&c| c as u64).product::<u64>();
            if total > MAX_GRID_SPHERES {
                return Err(
                    self.err(span, format!("a sphere grid of {total} spheres is over the limit of {MAX_GRID_SPHERES}"))
                );
            }
            let material = lookup(&g.material)?;
            for k in 0..g.counts[2] {
                for j in 0..g.counts[1] {
                    for i in 0..g.counts[0] {
                        let center = g.origin.0 + g.spacing.0 * Vec3::new(i as f32, j as f32, k as f32);
                        if !center.is_finite() {
                            return Err(self.err(span, "the sphere grid reaches beyond what 32-bit floats can hold"));
                        }
                        push(Sphere::new(center, g.radius.0).into(), material);
                    }
                }
            }
        }
        for p in def.plane {
            let Some(plane) = Plane::new(p.normal.get_ref().0, p.point.0) else {
                return Err(self.err(p.normal.span(), "a plane needs a non-zero normal"));
            };
            push(plane.into(), lookup(&p.material)?);
        }
        for b in def.boxes {
            let span = b.span();
            let b = b.into_inner();
            if !b.min.0.cmplt(b.max.0).all() {
                return Err(self.err(
                    span,
                    format!("a box needs min < max on every axis, found min {} and max {}", b.min.0, b.max.0),
                ));
            }
            push(AaBox::new(b.min.0, b.max.0).into(), lookup(&b.material)?);
        }
        for t in def.triangle {
            let span = t.span();
            let t = t.into_inner();
            let tri = Triangle::new(t.vertices[0].0, t.vertices[1].0, t.vertices[2].0);
            if tri.is_degenerate() {
                return Err(
                    self.err(span, "a triangle needs three vertices that are not on one line (its area is zero)")
                );
            }
            push(tri.into(), lookup(&t.material)?);
        }
        for r in def.rectangle {
            let span = r.span();
            let r = r.into_inner();
            let (c, e1, e2) = (r.corner.0, r.edge1.0, r.edge2.0);
            let material = lookup(&r.material)?;
            for [a, b, d] in [[c, c + e1, c + e1 + e2], [c, c + e1 + e2, c + e2]] {
                let tri = Triangle::new(a, b, d);
                if tri.is_degenerate() || !(a + b + d).is_finite() {
                    return Err(self.err(
                        span,
                        "a rectangle needs two edges that are not zero, not parallel, and within 32-bit floats",
                    ));
                }
                push(tri.into(), material);
            }
        }
        for r in def.random_triangles {
            let material = lookup(&r.get_ref().material)?;
            push(self.random_triangles(r)?, material);
        }
        let mut scene =
            Scene { image, camera, lights, materials, material_names, textures, objects, environment: None, warnings };
        self.meshes(def.mesh, &mut scene)?;
        if let Some(env) = def.environment {
            scene.environment = Some(self.environment(env)?);
            if scene.image.background != Vec3::ZERO {
                scene
                    .warnings
                    .push("the scene has an [environment]: rays that escape see it, not the [image] background".into());
            }
        }
        Ok(scene)
    }

    fn image(&self, image: Spanned<ImageDef>) -> Result<ImageSettings, SceneError> {
        let span = image.span();
        let i = image.into_inner();
        let filter = self.filter(&i, span.clone())?;
        let (width, height) = (*i.width.get_ref(), *i.height.get_ref());
        ImageSettings::check_limits(width, height, i.samples, i.max_depth).map_err(|message| {
            let at = if width == 0 || width as u64 * height as u64 > crate::model::MAX_PIXELS {
                i.width.span()
            } else if height == 0 {
                i.height.span()
            } else {
                span
            };
            self.err(at, message)
        })?;
        if let Some(m) = &i.min_samples {
            let n = *m.get_ref();
            if !(2..=crate::model::MAX_SAMPLES).contains(&n) {
                let max = crate::model::MAX_SAMPLES;
                return Err(
                    self.err(m.span(), format!("min_samples = {n}: expected 2 to {max} (two halves of samples)"))
                );
            }
        }
        let exposure = match i.exposure {
            Some(e) if e.get_ref().0.abs() > crate::model::MAX_EXPOSURE => {
                return Err(self.err(
                    e.span(),
                    format!(
                        "an exposure of {} stops: expected -{max} to {max}",
                        e.get_ref().0,
                        max = crate::model::MAX_EXPOSURE
                    ),
                ));
            }
            Some(e) => e.get_ref().0,
            None => 0.0,
        };
        Ok(ImageSettings {
            width,
            height,
            samples: i.samples,
            max_depth: i.max_depth,
            min_contribution: i.min_contribution.map_or(0.0, |f| f.0),
            noise_threshold: i.noise_threshold.map_or(0.0, |f| f.0),
            min_samples: i.min_samples.map(|m| *m.get_ref()),
            noise_allocation: i.noise_allocation,
            background: i.background.map_or(Vec3::ZERO, |c| c.0),
            ambient: i.ambient.map_or(Vec3::ZERO, |c| c.0),
            seed: i.seed,
            sampler: i.sampler,
            integrator: i.integrator,
            clamp: i.clamp.map(|c| c.0),
            output: crate::model::OutputSettings { exposure, tonemap: i.tonemap, exr_half: i.exr_half },
            filter,
            texture_filter: i.texture_filter,
        })
    }

    /// `filter`, `filter_radius` and `filter_sigma` (see [`PixelFilter`]).
    fn filter(&self, i: &ImageDef, image: Range<usize>) -> Result<PixelFilter, SceneError> {
        let radius = match &i.filter_radius {
            None => None,
            Some(r) => {
                let (x, y) = match *r.get_ref() {
                    FilterRadius::One(v) => (v, v),
                    FilterRadius::Two([x, y]) => (x, y),
                };
                if !(x > 0.0 && y > 0.0 && x <= MAX_FILTER_RADIUS as f64 && y <= MAX_FILTER_RADIUS as f64) {
                    return Err(self.err(
                        r.span(),
                        format!("a filter radius must be more than 0 and at most {MAX_FILTER_RADIUS} pixels"),
                    ));
                }
                Some((Vec2::new(x as f32, y as f32), r.span()))
            }
        };
        let name = i.filter.as_ref().map_or("box", |n| n.get_ref().as_str());
        let Some(filter) =
            PixelFilter::named(name, radius.as_ref().map(|r| r.0), i.filter_sigma.as_ref().map(|s| s.get_ref().0))
        else {
            let at = i.filter.as_ref().map_or(image, |n| n.span());
            return Err(
                self.err(at, format!("unknown filter `{name}`: expected \"box\", \"triangle\" or \"gaussian\""))
            );
        };
        if let (Some(s), false) = (&i.filter_sigma, matches!(filter, PixelFilter::Gaussian { .. })) {
            return Err(self.err(s.span(), "`filter_sigma` is for `filter = \"gaussian\"`"));
        }
        Ok(filter)
    }

    fn camera(&self, camera: Spanned<CameraDef>) -> Result<Camera, SceneError> {
        let span = camera.span();
        let c = camera.into_inner();
        let position = c.position.0;
        let look_at = c.look_at.get_ref().0;
        let view = look_at - position;
        if view.length() <= 0.0 || !view.is_finite() {
            return Err(self.err(c.look_at.span(), "the camera's look_at must differ from its position"));
        }
        let (up, up_span) = match &c.up {
            Some(u) => (u.get_ref().0, u.span()),
            None => (Vec3::Y, span.clone()),
        };
        let side = view.normalize().cross(up.normalize_or_zero());
        if side.length() <= 1e-6 || side.is_nan() {
            return Err(self.err(
                up_span,
                format!("the camera's up vector {up} is zero or parallel to its view direction {view}"),
            ));
        }
        let fov_degrees = match &c.fov {
            Some(f) if !(f.get_ref().0 > 0.0 && f.get_ref().0 < 180.0) => {
                return Err(self.err(
                    f.span(),
                    format!("a field of view of {} degrees: expected more than 0 and less than 180", f.get_ref().0),
                ));
            }
            Some(f) => f.get_ref().0,
            None => 45.0,
        };
        let distance = view.length();
        let projection = match (c.projection, &c.view_height) {
            (ProjectionKind::Perspective, Some(h)) => {
                return Err(self.err(h.span(), "`view_height` is for `projection = \"orthographic\"`"));
            }
            (ProjectionKind::Perspective, None) => Projection::Perspective,
            (ProjectionKind::Orthographic, h) => Projection::Orthographic {
                // By default, the size the perspective view has at the look-at point.
                view_height: h
                    .as_ref()
                    .map_or(2.0 * distance * (fov_degrees.to_radians() * 0.5).tan(), |h| h.get_ref().0),
            },
        };
        Ok(Camera {
            position,
            look_at,
            up,
            fov_degrees,
            projection,
            lens_radius: c.aperture.map_or(0.0, |a| a.0 * 0.5),
            focus_distance: c.focus_distance.map_or(distance, |f| f.0),
            left_handed: false,
        })
    }
}

fn light_power(color: Option<crate::numbers::Color>, intensity: Option<crate::numbers::NonNegative>) -> Vec3 {
    color.map_or(Vec3::ONE, |c| c.0) * intensity.map_or(1.0, |i| i.0)
}
