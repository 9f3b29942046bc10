//! What decides an image's pixels besides the scene file, shared by `render` and `farm`: the
//! scene overrides (`-D key=value`, applied to the scene's document before it is validated), the
//! size, samples, integrator and structure overrides, applied to the scene, and the digest that
//! tiles record of the result (see englobe-render's `tile` module). Keeping them in one place is
//! what lets `farm` hand every task the same options through [`ImageOptions::to_args`], and the
//! digest cover them all, because it is computed on the scene after they are applied.

use clap::{Args, ValueEnum};
use englobe::AccelKind;
use englobe_scene::{ImageSettings, IntegratorKind, OutputSettings, Override, Scene, ToneMap};

/// Overrides of the scene's image settings, and the structure to trace with.
#[derive(Args, Clone, Debug)]
pub struct ImageOptions {
    /// Set any value of the scene by its dotted path, as a TOML value (repeatable):
    /// `-D camera.fov=40 -D point_light.0.intensity=60 -D image.samples=64`; a number indexes an
    /// array such as `[[point_light]]`, one past its end adds an entry, a bare word is a string.
    #[arg(short = 'D', long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<Override>,
    /// Camera position, as X,Y,Z (the same as -D camera.position=[X,Y,Z]).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_point, allow_hyphen_values = true)]
    pub look_from: Option<String>,
    /// The point the camera looks at, as X,Y,Z (the same as -D camera.look_at=[X,Y,Z]).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_point, allow_hyphen_values = true)]
    pub look_at: Option<String>,
    /// Vertical field of view in degrees (the same as -D camera.fov=DEGREES).
    #[arg(long, value_name = "DEGREES", value_parser = parse_fov)]
    pub fov: Option<f32>,
    /// Image width in pixels (overrides the scene; alone, the height follows the scene's aspect
    /// ratio).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels (overrides the scene; alone, the width follows the scene's aspect
    /// ratio).
    #[arg(long)]
    pub height: Option<u32>,
    /// Scale the image size by this factor, after --width and --height: 0.25 for a quick preview.
    #[arg(long, value_parser = parse_scale)]
    pub scale: Option<f64>,
    /// Samples per pixel (overrides the scene); with a noise threshold, the most a pixel takes.
    #[arg(long)]
    pub spp: Option<u32>,
    /// Adaptive sampling: every 8x8 block of pixels stops once its estimated relative error falls
    /// under this (0.01 is fine, 0.05 a preview; 0 turns it off); the same as
    /// -D image.noise_threshold=T. The first pass is image.min_samples (default, as Cycles:
    /// 16 / T^0.3, so 64 at 0.01). -D image.noise_allocation=mse shares the samples for the
    /// least squared error instead of an even noise.
    #[arg(long, value_name = "T", value_parser = parse_threshold)]
    pub noise_threshold: Option<f32>,
    /// Acceleration structure: bvh-wide (the fast path, eight-wide at both levels), none (brute
    /// force), bvh-seed, bvh-seed-ordered, bvh-sah, bvh-ploc, bvh-sweep, kdtree, grid
    #[arg(long, default_value = "bvh-wide", value_parser = parse_accel)]
    pub accel: AccelKind,
    /// Light transport: whitted (the seed's recursion) or path (Monte Carlo path tracing);
    /// overrides the scene's `integrator`.
    #[arg(long, value_parser = parse_integrator)]
    pub integrator: Option<IntegratorKind>,
    #[command(flatten)]
    pub output: OutputOptions,
}

/// How the image is written, shared by `render`, `farm` and `assemble`: none of it changes a
/// linear pixel, so tiles of one render may be assembled with other values.
#[derive(Args, Clone, Debug, Default)]
pub struct OutputOptions {
    /// Exposure in stops for PNG output: values are multiplied by 2^EV before the tone map
    /// (overrides the scene's `exposure`; EXR keeps the linear values).
    #[arg(long, value_name = "EV", value_parser = parse_exposure, allow_hyphen_values = true)]
    pub exposure: Option<f32>,
    /// Tone map for PNG output: none (values clipped) or filmic (an ACES-like curve); overrides
    /// the scene's `tonemap`.
    #[arg(long, value_parser = parse_tonemap)]
    pub tonemap: Option<ToneMap>,
    /// Write OpenEXR output in 16-bit half floats (the same as `[image] exr_half = true`).
    #[arg(long)]
    pub half: bool,
}

impl OutputOptions {
    /// `settings` with these options' overrides.
    pub fn apply(&self, settings: OutputSettings) -> OutputSettings {
        OutputSettings {
            exposure: self.exposure.unwrap_or(settings.exposure),
            tonemap: self.tonemap.unwrap_or(settings.tonemap),
            exr_half: self.half || settings.exr_half,
        }
    }

    /// The same options as command-line arguments.
    pub fn to_args(&self) -> Vec<String> {
        let mut args = Vec::new();
        if let Some(e) = self.exposure {
            args.extend(["--exposure".to_owned(), e.to_string()]);
        }
        if let Some(t) = self.tonemap {
            args.extend(["--tonemap".to_owned(), t.name().to_owned()]);
        }
        if self.half {
            args.push("--half".to_owned());
        }
        args
    }
}

impl ImageOptions {
    /// Writes the image overrides into the scene's image settings (the `-D` overrides are applied
    /// when the scene is read, see [`crate::render_cmd::read_scene`]), and checks the result.
    pub fn apply(&self, scene: &mut Scene) -> anyhow::Result<()> {
        let image = &mut scene.image;
        (image.width, image.height) = image_size(image, self.width, self.height, self.scale);
        image.samples = self.spp.unwrap_or(image.samples);
        image.noise_threshold = self.noise_threshold.unwrap_or(image.noise_threshold);
        image.integrator = self.integrator.unwrap_or(image.integrator);
        image.output = self.output.apply(image.output);
        ImageSettings::check_limits(image.width, image.height, image.samples, image.max_depth)
            .map_err(anyhow::Error::msg)
    }

    /// The overrides of the scene's document: the camera options, then the `-D` ones (which come
    /// later, so they win).
    pub fn overrides(&self) -> Vec<Override> {
        let camera = [
            ("camera.position", self.look_from.clone()),
            ("camera.look_at", self.look_at.clone()),
            ("camera.fov", self.fov.map(|f| f.to_string())),
        ];
        let camera =
            camera.into_iter().filter_map(|(key, value)| Some(Override { key: key.to_owned(), value: value? }));
        camera.chain(self.set.iter().cloned()).collect()
    }

    /// The same options as command-line arguments, to pass them on to another `englobe render`.
    pub fn to_args(&self) -> Vec<String> {
        let mut args = vec!["--accel".to_owned(), self.accel.name().to_owned()];
        for o in &self.set {
            args.extend(["--set".to_owned(), format!("{}={}", o.key, o.value)]);
        }
        let mut push = |flag: &str, value: Option<String>| {
            if let Some(v) = value {
                args.extend([flag.to_owned(), v]);
            }
        };
        push("--look-from", self.look_from.as_ref().map(|p| p.trim_matches(['[', ']']).replace(' ', "")));
        push("--look-at", self.look_at.as_ref().map(|p| p.trim_matches(['[', ']']).replace(' ', "")));
        push("--fov", self.fov.map(|v| v.to_string()));
        push("--width", self.width.map(|v| v.to_string()));
        push("--height", self.height.map(|v| v.to_string()));
        push("--scale", self.scale.map(|v| v.to_string()));
        push("--spp", self.spp.map(|v| v.to_string()));
        push("--noise-threshold", self.noise_threshold.map(|v| v.to_string()));
        push("--integrator", self.integrator.map(|i| i.name().to_owned()));
        args.extend(self.output.to_args());
        args
    }
}

/// How `--tile K/N` cuts the image into strips.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum Balance {
    /// Strips of equal height.
    #[default]
    Area,
    /// Strips of equal predicted cost, from a first pass of the cost AOV on every 4th pixel of
    /// every 4th row (each task makes the same pass, so all agree on the cut).
    Cost,
}

/// The digest of the pixels `scene` (with the overrides applied) gives under `accel`, cut as
/// `balance` says (tiles of different cuts must not be mixed).
pub fn render_digest(scene: &Scene, accel: AccelKind, balance: Balance) -> String {
    let balance = balance.to_possible_value().expect("no variant is skipped");
    englobe_render::digest::scene_digest(
        scene,
        &format!("accel={} aov=color balance={}", accel.name(), balance.get_name()),
    )
}

/// The image size that `width`, `height` and `scale` ask for, from the scene's `image`: a width
/// or height alone keeps the scene's aspect ratio, and the scale applies to the result (at least
/// one pixel either way).
pub fn image_size(image: &ImageSettings, width: Option<u32>, height: Option<u32>, scale: Option<f64>) -> (u32, u32) {
    let aspect = image.width as f64 / image.height.max(1) as f64;
    let pixels = |x: f64| x.round().clamp(1.0, u32::MAX as f64) as u32;
    let (w, h) = match (width, height) {
        (Some(w), Some(h)) => (w, h),
        (Some(w), None) => (w, pixels(w as f64 / aspect)),
        (None, Some(h)) => (pixels(h as f64 * aspect), h),
        (None, None) => (image.width, image.height),
    };
    match scale {
        Some(s) => (pixels(w as f64 * s), pixels(h as f64 * s)),
        None => (w, h),
    }
}

fn parse_fov(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(x) if x > 0.0 && x < 180.0 => Ok(x),
        _ => Err(format!("`{s}`: expected degrees, more than 0 and less than 180")),
    }
}

/// `X,Y,Z` as the TOML array `[X, Y, Z]`.
fn parse_point(s: &str) -> Result<String, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    match parts.iter().map(|p| p.parse::<f32>()).collect::<Result<Vec<f32>, _>>() {
        Ok(v) if v.len() == 3 && v.iter().all(|x| x.is_finite()) => Ok(format!("[{}]", parts.join(", "))),
        _ => Err(format!("`{s}`: expected three numbers X,Y,Z, such as 0,1.5,-6")),
    }
}

fn parse_threshold(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
        _ => Err(format!("`{s}`: expected a relative error of 0 or more, such as 0.01")),
    }
}

pub fn parse_scale(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x > 0.0 && x <= 64.0 => Ok(x),
        _ => Err(format!("`{s}`: expected a factor greater than 0 and at most 64, such as 0.25")),
    }
}

fn parse_exposure(s: &str) -> Result<f32, String> {
    let most = englobe_scene::model::MAX_EXPOSURE;
    match s.parse::<f32>() {
        Ok(x) if x.abs() <= most => Ok(x),
        _ => Err(format!("`{s}`: expected stops from -{most} to {most}, such as 1.5 or -2")),
    }
}

fn parse_tonemap(s: &str) -> Result<ToneMap, String> {
    match s {
        "none" => Ok(ToneMap::None),
        "filmic" => Ok(ToneMap::Filmic),
        _ => Err(format!("unknown tone map `{s}`; expected none or filmic")),
    }
}

fn parse_integrator(s: &str) -> Result<IntegratorKind, String> {
    match s {
        "whitted" => Ok(IntegratorKind::Whitted),
        "path" => Ok(IntegratorKind::Path),
        _ => Err(format!("unknown integrator `{s}`; expected whitted or path")),
    }
}

/// Reads a structure's name.
pub fn parse_accel(s: &str) -> Result<AccelKind, String> {
    s.parse().map_err(|e: englobe::accel::UnknownAccel| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_width_alone_keeps_the_aspect_ratio() {
        let scene = englobe_scene::parse_scene(englobe_render::DEFAULT_SCENE, "default.toml".as_ref()).unwrap();
        let image = &scene.image;
        assert_eq!((image.width, image.height), (640, 480));
        assert_eq!(image_size(image, Some(160), None, None), (160, 120));
        assert_eq!(image_size(image, None, Some(120), None), (160, 120));
        assert_eq!(image_size(image, Some(100), Some(100), None), (100, 100));
        assert_eq!(image_size(image, None, None, Some(0.25)), (160, 120));
        assert_eq!(image_size(image, Some(1), None, Some(0.01)), (1, 1));
    }
}
