//! The options block (`Camera`, `Film`, `Sampler`, `Integrator`, `PixelFilter`) as englobe's
//! camera and image settings, read when the file is done since they depend on each other.
//!
//! The camera: pbrt's camera space has `x` to the image's right, `y` up and `z` forward, and the
//! transformation matrix at `Camera` maps the world to it (pbrt-v4, "Cameras" in the file format's
//! documentation). Its inverse gives the eye, the view direction and the image's right and up in
//! the world. pbrt's `fov` spans the shorter image axis (`PerspectiveCamera::Create`); englobe's
//! spans the vertical one, so portrait images convert it. When the image's right is `up x forward`
//! (pbrt's `LookAt`, a left-handed frame), englobe's camera is told so ([`Camera::left_handed`]),
//! since its own frame puts the right at `forward x up`: pbrt's images are never mirrored.

use englobe::{Aabb, Vec2, Vec3};
use glam::{DMat3, DVec3};

use super::builder::{Builder, Decl};
use super::params::Params;
use super::source::{Place, Res, fail};
use crate::model::{Camera, ImageSettings, IntegratorKind, MAX_DEPTH, Projection, SamplerKind};
use crate::pixel_filter::PixelFilter;

impl Builder {
    /// Keeps an options directive (`Camera` also keeps the transformation matrix, and names it
    /// the "camera" coordinate system, as pbrt does).
    pub fn option_directive(&mut self, at: Place, directive: &str, kind: &str, params: Params) -> Res<()> {
        self.require_options(at, directive)?;
        let decl = Decl { kind: kind.to_owned(), params, at };
        let slot = match directive {
            "Camera" => {
                let ctm = self.gs.ctm;
                if glam::DMat3::from_mat4(ctm).determinant() == 0.0 || !super::transform::is_affine(&ctm) {
                    return fail(at, "Camera: the transformation matrix is singular or projective");
                }
                self.named_coordinates.insert("camera".into(), ctm.inverse());
                self.camera = Some((decl, ctm));
                return Ok(());
            }
            "Film" => &mut self.film,
            "Sampler" => &mut self.sampler,
            "Integrator" => &mut self.integrator,
            _ => &mut self.filter,
        };
        if let Some(old) = slot.replace(decl) {
            // pbrt keeps the last; say so, since the first is then lost.
            let at_old = old.at;
            self.report.ignored(at_old, &format!("{directive} twice"), || {
                format!("{directive} is given again later: this one is replaced")
            })?;
        }
        Ok(())
    }

    /// The image settings and the camera. `bounds` (the scene's) places the camera's look-at
    /// point on its view axis nearest the scene's centre.
    pub fn image_and_camera(&mut self, bounds: Aabb) -> Res<(ImageSettings, Camera)> {
        let film_at = self.film.as_ref().map_or(Place::START, |d| d.at);
        let sampler_at = self.sampler.as_ref().map_or(film_at, |d| d.at);
        let (width, height) = self.film_size()?;
        let (samples, seed, sampler) = self.sampler_options()?;
        let max_depth = self.integrator_options()?;
        let filter = self.pixel_filter()?;
        if let Err(message) = ImageSettings::check_limits(width, height, samples, max_depth) {
            let size_ok = ImageSettings::check_limits(width, height, 1, 0).is_ok();
            return fail(if size_ok { sampler_at } else { film_at }, message);
        }
        let camera = self.camera_settings(width, height, bounds)?;
        let image = ImageSettings {
            width,
            height,
            samples,
            max_depth,
            min_contribution: 0.0,
            background: self.background,
            ambient: Vec3::ZERO,
            seed: self.option_seed.unwrap_or(seed),
            sampler,
            integrator: IntegratorKind::Path,
            filter,
            clamp: None,
            output: Default::default(),
            noise_threshold: 0.0,
            min_samples: None,
            noise_allocation: Default::default(),
            texture_filter: Default::default(),
        };
        Ok((image, camera))
    }

    fn film_size(&mut self) -> Res<(u32, u32)> {
        let Some(d) = self.film.take() else { return Ok((1280, 720)) };
        let what = format!("Film \"{}\"", d.kind);
        if !matches!(d.kind.as_str(), "rgb" | "image" | "gbuffer" | "spectral") {
            self.report.approximated(d.at, "film type", || format!("{what}: read as pbrt's \"rgb\" film"))?;
        }
        let size = |v: Option<i64>, default: i64, name: &str| -> Res<u32> {
            match v.unwrap_or(default) {
                n if (1..=i64::from(u32::MAX)).contains(&n) => Ok(n as u32),
                n => fail(
                    d.params.touch(name).map_or(d.at, |p| p.at),
                    format!("{what}: {name} {n}: expected at least 1"),
                ),
            }
        };
        let width = size(d.params.integer("xresolution")?, 1280, "xresolution")?;
        let height = size(d.params.integer("yresolution")?, 720, "yresolution")?;
        if let Some((name, name_at)) = d.params.string("filename")? {
            let name = name.to_owned();
            self.report.ignored(name_at, "film filename", || {
                format!("{what}: the output file \"{name}\" is not used: englobe writes where -o says")
            })?;
        }
        for (p, why) in [("cropwindow", "crop windows"), ("pixelbounds", "pixel bounds")] {
            if let Some(param) = d.params.touch(p) {
                let at = param.at;
                self.report.skipped(at, &format!("film {p}"), || {
                    format!("{what}: {why} are not supported: the whole image is rendered")
                })?;
            }
        }
        let default_ratio = |v: Option<f64>, default: f64| v.is_none_or(|x| (x - default).abs() < 1e-9);
        if !default_ratio(d.params.float("iso")?, 100.0) || !default_ratio(d.params.float("exposuretime")?, 1.0) {
            self.report.skipped(d.at, "film exposure", || {
                format!("{what}: iso and exposuretime other than 100 and 1 are not applied")
            })?;
        }
        if let Some(param) = d
            .params
            .touch("sensor")
            .filter(|p| !matches!(&p.values, super::params::Values::Strings(s) if s[0] == "cie1931"))
        {
            let at = param.at;
            self.report.skipped(at, "film sensor", || {
                format!("{what}: camera sensor curves are not supported: CIE 1931 is used")
            })?;
        }
        for p in ["savefp16", "diagonal", "whitebalance", "maxcomponentvalue", "writefp16"] {
            if let Some(param) = d.params.touch(p) {
                let (at, shown) = (param.at, param.shown());
                self.report.ignored(at, &format!("film {p}"), || format!("{what}: {shown} is not used"))?;
            }
        }
        self.report_unused(&d.params, &format!("Film {}", d.kind), &what)?;
        Ok((width, height))
    }

    /// Samples per pixel, seed and sampler. pbrt-v4's default, `zsobol`, and its other Sobol
    /// samplers are englobe's Sobol sampler (Owen-scrambled, padded per pixel: pbrt's
    /// `paddedsobol`); `independent` is the independent one; the stratified, Halton and PMJ02BN
    /// samplers, low-discrepancy too, are rendered with the Sobol one, reported.
    fn sampler_options(&mut self) -> Res<(u32, u64, SamplerKind)> {
        let Some(d) = self.sampler.take() else { return Ok((16, 0, SamplerKind::Sobol)) };
        let what = format!("Sampler \"{}\"", d.kind);
        let samples = if d.kind == "stratified" {
            let x = d.params.integer("xsamples")?.unwrap_or(4);
            let y = d.params.integer("ysamples")?.unwrap_or(4);
            d.params.touch("jitter");
            x.saturating_mul(y)
        } else {
            d.params.integer("pixelsamples")?.unwrap_or(16)
        };
        let samples = match u32::try_from(samples) {
            Ok(n) if n >= 1 => n,
            _ => return fail(d.at, format!("{what}: {samples} samples per pixel: expected at least 1")),
        };
        let seed = d.params.integer("seed")?.unwrap_or(0) as u64;
        d.params.touch("randomization");
        let sampler = match d.kind.as_str() {
            "independent" => SamplerKind::Independent,
            "sobol" | "zsobol" | "paddedsobol" => SamplerKind::Sobol,
            _ => {
                let kind = d.kind.clone();
                self.report.approximated(d.at, "sampler type", || {
                    format!(
                        "{what}: englobe draws Owen-scrambled Sobol samples, not \"{kind}\" ones: the same picture \
                         with other noise"
                    )
                })?;
                SamplerKind::Sobol
            }
        };
        self.report_unused(&d.params, &format!("Sampler {}", d.kind), &what)?;
        Ok((samples, seed, sampler))
    }

    fn integrator_options(&mut self) -> Res<u32> {
        let Some(d) = self.integrator.take() else { return Ok(5) };
        let what = format!("Integrator \"{}\"", d.kind);
        match d.kind.as_str() {
            "path" | "volpath" => {}
            "bdpt" | "mlt" | "sppm" | "simplepath" | "simplevolpath" | "lightpath" | "randomwalk" => {
                let kind = d.kind.clone();
                self.report.ignored(d.at, "integrator type", || {
                    format!(
                        "{what}: rendered by englobe's path tracer, which converges to the same picture as \"{kind}\""
                    )
                })?;
            }
            _ => {
                self.report.approximated(d.at, "integrator other", || {
                    format!(
                        "{what}: this integrator computes another quantity than radiance: englobe's path tracer is used"
                    )
                })?;
            }
        }
        let depth = d.params.integer("maxdepth")?.unwrap_or(5);
        if depth < 0 {
            return fail(
                d.params.touch("maxdepth").map_or(d.at, |p| p.at),
                format!("{what}: maxdepth {depth} is negative"),
            );
        }
        let depth = if depth > MAX_DEPTH as i64 {
            self.report.approximated(d.at, "maxdepth", || {
                format!("{what}: maxdepth {depth} is cut to englobe's limit, {MAX_DEPTH}")
            })?;
            MAX_DEPTH
        } else {
            depth as u32
        };
        if d.params.bool("regularize")?.unwrap_or(false) {
            self.report.skipped(d.at, "regularize", || format!("{what}: path regularization is not supported"))?;
        }
        for p in [
            "lightsampler",
            "samplelights",
            "samplebsdf",
            "uselights",
            "usebsdf",
            "visualizestrategies",
            "visualizeweights",
        ] {
            params_touch(&d.params, p);
        }
        self.report_unused(&d.params, &format!("Integrator {}", d.kind), &what)?;
        Ok(depth)
    }

    fn pixel_filter(&mut self) -> Res<PixelFilter> {
        let Some(d) = self.filter.take() else {
            return Ok(PixelFilter::Gaussian { radius: Vec2::splat(1.5), sigma: 0.5 });
        };
        let what = format!("PixelFilter \"{}\"", d.kind);
        let radius = |default: f32| -> Res<Vec2> {
            let axis = |v4: &str, v3: &str| -> Res<f32> {
                Ok(d.params.float(v4)?.or(d.params.float(v3)?).map_or(default, |r| r as f32))
            };
            Ok(Vec2::new(axis("xradius", "xwidth")?, axis("yradius", "ywidth")?))
        };
        let filter = match d.kind.as_str() {
            "box" => PixelFilter::Box { radius: radius(0.5)? },
            "triangle" => PixelFilter::Triangle { radius: radius(2.0)? },
            "gaussian" => {
                let r = radius(if d.params.has("alpha") { 2.0 } else { 1.5 })?;
                let sigma = match (d.params.float("sigma")?, d.params.float("alpha")?) {
                    (Some(s), _) => s,
                    // pbrt-v3's Gaussian is exp(-alpha x^2).
                    (None, Some(a)) if a > 0.0 => (0.5 / a).sqrt(),
                    _ => 0.5,
                };
                PixelFilter::Gaussian { radius: r, sigma: sigma as f32 }
            }
            _ => {
                for p in params_names(&d.params) {
                    params_touch(&d.params, &p);
                }
                self.report.approximated(d.at, "filter type", || {
                    format!("{what}: this filter is not supported: pbrt's default, a Gaussian of radius 1.5 and sigma 0.5, is used")
                })?;
                PixelFilter::Gaussian { radius: Vec2::splat(1.5), sigma: 0.5 }
            }
        };
        if let Err(message) = filter.check() {
            return fail(d.at, format!("{what}: {message}"));
        }
        self.report_unused(&d.params, &format!("PixelFilter {}", d.kind), &what)?;
        Ok(filter)
    }

    fn camera_settings(&mut self, width: u32, height: u32, bounds: Aabb) -> Res<Camera> {
        let (d, camera_from_world) = match self.camera.take() {
            Some(c) => c,
            None => {
                (Decl { kind: "perspective".into(), params: Params::none(), at: Place::START }, glam::DMat4::IDENTITY)
            }
        };
        let what = format!("Camera \"{}\"", d.kind);
        let m = camera_from_world.inverse();
        let eye = m.transform_point3(DVec3::ZERO);
        let linear = DMat3::from_mat4(m);
        let (right, up, forward) = (linear.x_axis, linear.y_axis, linear.z_axis);
        let lengths = [right.length(), up.length(), forward.length()];
        let skew = right.normalize().dot(up.normalize()).abs()
            + up.normalize().dot(forward.normalize()).abs()
            + forward.normalize().dot(right.normalize()).abs();
        if (lengths[0] - lengths[2]).abs() > 1e-6 * lengths[2]
            || (lengths[1] - lengths[2]).abs() > 1e-6 * lengths[2]
            || skew > 1e-6
        {
            self.report.approximated(d.at, "camera shear", || {
                format!("{what}: the camera transform has a non-uniform scale or a shear: only its rotation is used")
            })?;
        }
        let f = forward.normalize();
        let u = (up - f * up.dot(f)).try_normalize();
        let (Some(u), true) = (u, eye.is_finite() && f.is_finite()) else {
            return fail(d.at, format!("{what}: the camera transform does not give a view direction and an up vector"));
        };
        let left_handed = f.cross(u).dot(right) < 0.0;
        let frame = d.params.float("frameaspectratio")?.unwrap_or(width as f64 / height as f64);
        if (frame - width as f64 / height as f64).abs() > 1e-6 * frame {
            self.report.approximated(d.at, "frame aspect", || {
                format!(
                    "{what}: a frame aspect ratio other than the image's ({frame}) is not supported: pixels are square"
                )
            })?;
        }
        if let Some(p) = d.params.touch("screenwindow") {
            let at = p.at;
            self.report.approximated(at, "screen window", || {
                format!("{what}: screenwindow is not supported: the full frame is used")
            })?;
        }
        for p in ["shutteropen", "shutterclose"] {
            d.params.touch(p);
        }
        let lens_radius = d.params.float("lensradius")?.unwrap_or(0.0);
        let focal = d.params.float("focaldistance")?.unwrap_or(1e6);
        if !(lens_radius >= 0.0) || !(focal > 0.0) {
            return fail(d.at, format!("{what}: lensradius must be at least 0 and focaldistance positive"));
        }
        // The shorter axis spans the screen window [-1, 1]; englobe's values are vertical.
        let vertical_scale = if frame >= 1.0 { 1.0 } else { 1.0 / frame };
        let projection = match d.kind.as_str() {
            "orthographic" => Projection::Orthographic { view_height: (2.0 * vertical_scale * lengths[1]) as f32 },
            kind => {
                if kind != "perspective" {
                    self.report.skipped(d.at, "camera type", || {
                        format!(
                            "{what}: cameras of this type are not supported: a perspective camera of fov 90 is used"
                        )
                    })?;
                    for p in params_names(&d.params) {
                        params_touch(&d.params, &p);
                    }
                }
                Projection::Perspective
            }
        };
        let fov = if d.kind == "perspective" { d.params.float("fov")?.unwrap_or(90.0) } else { 90.0 };
        if !(fov > 0.0 && fov < 180.0) {
            return fail(
                d.params.touch("fov").map_or(d.at, |p| p.at),
                format!("{what}: fov {fov}: expected more than 0 and less than 180 degrees"),
            );
        }
        let vertical = 2.0 * ((fov.to_radians() / 2.0).tan() * vertical_scale).atan();
        self.report_unused(&d.params, &format!("Camera {}", d.kind), &what)?;
        // Look at the point of the view axis nearest the scene's centre (any point of the axis
        // gives the same picture; this one makes a turntable turn about the scene).
        let distance = if bounds.is_empty() { 1.0 } else { (bounds.center().as_dvec3() - eye).dot(f) };
        let distance = if distance > 1e-6 && distance.is_finite() { distance } else { 1.0 };
        let position = eye.as_vec3();
        let camera = Camera {
            position,
            look_at: (eye + f * distance).as_vec3(),
            up: u.as_vec3(),
            fov_degrees: vertical.to_degrees() as f32,
            projection,
            lens_radius: lens_radius as f32,
            focus_distance: if lens_radius > 0.0 { focal as f32 } else { distance as f32 },
            left_handed,
        };
        if camera.look_at == camera.position || !camera.look_at.is_finite() {
            return fail(d.at, format!("{what}: the camera lies beyond the range of 32-bit floats"));
        }
        Ok(camera)
    }
}

fn params_touch(params: &Params, name: &str) {
    params.touch(name);
}

fn params_names(params: &Params) -> Vec<String> {
    params.unused().map(|p| p.name.clone()).collect()
}
