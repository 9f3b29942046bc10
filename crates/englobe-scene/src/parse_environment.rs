//! The `[environment]` table: a map file (read relative to the scene's folder), a constant colour,
//! or a sky gradient, with an intensity and a turn about +y (see [`crate::environment`]).

use std::sync::Arc;

use toml::Spanned;

use crate::environment::{Environment, Sky, load_environment_map};
use crate::error::SceneError;
use crate::format::EnvironmentDef;
use crate::parse::Converter;

impl Converter<'_> {
    /// The environment the table describes, with its map read and checked.
    pub(crate) fn environment(&self, def: Spanned<EnvironmentDef>) -> Result<Environment, SceneError> {
        let span = def.span();
        let d = def.into_inner();
        let gradient = d.zenith.is_some() || d.horizon.is_some() || d.ground.is_some();
        let kinds = [d.file.is_some(), d.color.is_some(), gradient].iter().filter(|&&k| k).count();
        if kinds != 1 {
            return Err(self.err(
                span,
                "an [environment] needs exactly one of `file` (a map), `color` (a constant) or `zenith` and \
                 `horizon` (a sky)",
            ));
        }
        let sky = if let Some(file) = &d.file {
            let path = self.dir.join(file.get_ref());
            let map = load_environment_map(&path).map_err(|e| {
                self.err(file.span(), format!("cannot load the environment map `{}`: {e}", file.get_ref()))
            })?;
            Sky::Map(Arc::new(map))
        } else if let Some(color) = &d.color {
            Sky::Constant(color.get_ref().0)
        } else {
            let (Some(zenith), Some(horizon)) = (&d.zenith, &d.horizon) else {
                let at = d.zenith.as_ref().or(d.horizon.as_ref()).or(d.ground.as_ref()).map_or(span, |c| c.span());
                return Err(self.err(at, "a sky needs both `zenith` and `horizon` (and optionally `ground`)"));
            };
            let horizon = horizon.get_ref().0;
            Sky::Gradient { zenith: zenith.get_ref().0, horizon, ground: d.ground.map_or(horizon, |g| g.get_ref().0) }
        };
        Ok(Environment {
            sky,
            intensity: d.intensity.map_or(1.0, |i| i.0),
            rotation_degrees: d.rotation.map_or(0.0, |r| r.0),
        })
    }
}

#[cfg(test)]
mod tests {
    use englobe::Vec3;

    use crate::environment::Sky;
    use crate::parse_scene;

    const HEAD: &str = "[image]\nwidth = 2\nheight = 2\n[camera]\nposition = [0, 0, -1]\nlook_at = [0, 0, 0]\n";

    #[test]
    fn a_sky_and_a_constant_are_read_with_their_defaults() {
        let s = parse_scene(
            &format!("{HEAD}[environment]\nzenith = [0.1, 0.2, 0.9]\nhorizon = [1, 1, 1]\n"),
            "s.toml".as_ref(),
        )
        .unwrap();
        let env = s.environment.unwrap();
        assert_eq!(env.sky, Sky::Gradient { zenith: Vec3::new(0.1, 0.2, 0.9), horizon: Vec3::ONE, ground: Vec3::ONE });
        assert_eq!((env.intensity, env.rotation_degrees), (1.0, 0.0));
        let text = format!("{HEAD}[environment]\ncolor = [2, 2, 2]\nintensity = 0.5\nrotation = 90\n");
        let env = parse_scene(&text, "s.toml".as_ref()).unwrap().environment.unwrap();
        assert_eq!((env.sky, env.intensity, env.rotation_degrees), (Sky::Constant(Vec3::splat(2.0)), 0.5, 90.0));
    }

    #[test]
    fn an_environment_that_says_too_much_or_too_little_is_refused_where_it_is() {
        for (table, line, expected) in [
            ("color = [1, 1, 1]\nzenith = [1, 1, 1]\n", 7, "exactly one of"),
            ("intensity = 2\n", 7, "exactly one of"),
            ("zenith = [1, 1, 1]\n", 8, "both `zenith` and `horizon`"),
            ("file = \"missing.exr\"\n", 8, "cannot load the environment map `missing.exr`"),
            ("color = [1, -1, 1]\n", 8, "at least 0"),
        ] {
            let e = parse_scene(&format!("{HEAD}[environment]\n{table}"), "dir/s.toml".as_ref()).unwrap_err();
            let at = e.location().unwrap();
            assert_eq!(at.line, line, "{e}");
            assert!(e.to_string().contains(expected), "{e}");
        }
        // The map is looked for beside the scene file, and its error names it there.
        let e =
            parse_scene(&format!("{HEAD}[environment]\nfile = \"missing.exr\"\n"), "dir/s.toml".as_ref()).unwrap_err();
        assert!(e.to_string().contains("dir/missing.exr: cannot read"), "{e}");
    }

    #[test]
    fn an_environment_with_a_background_warns_that_the_background_is_unused() {
        let text = format!(
            "{}[environment]\ncolor = [1, 1, 1]\n",
            HEAD.replace("[camera]", "background = [1, 0, 0]\n[camera]")
        );
        let s = parse_scene(&text, "s.toml".as_ref()).unwrap();
        assert!(s.warnings.iter().any(|w| w.contains("not the [image] background")), "{:?}", s.warnings);
    }
}
