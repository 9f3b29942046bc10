//! The directive loop: reads each directive with its own arguments and its parameter list from
//! the file on top of the include stack and hands it to the [`Builder`]. `Include` pushes a file
//! (text substitution, as in pbrt); `Import` pushes one whose changes to the graphics state are
//! undone when it ends. Relative file names are resolved as pbrt resolves them, against the main
//! file's folder, and then against the naming file's; an include cycle or a nesting deeper than
//! [`MAX_INCLUDE_DEPTH`] is an error at the `Include`.

use std::path::PathBuf;

use glam::DVec3;

use super::builder::{Active, Builder, Scope};
use super::lexer::{Kind, Lexer, Token};
use super::params::{Params, parse_params};
use super::source::{Fail, MAX_PBRT_TOTAL_BYTES, Place, Res, fail, read_text};
use super::transform;

/// Deepest nesting of `Include` and `Import`.
pub const MAX_INCLUDE_DEPTH: usize = 32;

/// Every directive of pbrt-v4 and pbrt-v3, for recognising where an unknown one's arguments end.
const DIRECTIVES: &[&str] = &[
    "Accelerator",
    "ActiveTransform",
    "AreaLightSource",
    "Attribute",
    "AttributeBegin",
    "AttributeEnd",
    "Camera",
    "ColorSpace",
    "ConcatTransform",
    "CoordSysTransform",
    "CoordinateSystem",
    "Film",
    "Identity",
    "Import",
    "Include",
    "Integrator",
    "LightSource",
    "LookAt",
    "MakeNamedMaterial",
    "MakeNamedMedium",
    "Material",
    "MediumInterface",
    "NamedMaterial",
    "ObjectBegin",
    "ObjectEnd",
    "ObjectInstance",
    "Option",
    "PixelFilter",
    "ReverseOrientation",
    "Rotate",
    "Sampler",
    "Scale",
    "Shape",
    "Texture",
    "Transform",
    "TransformBegin",
    "TransformEnd",
    "TransformTimes",
    "Translate",
    "WorldBegin",
    "WorldEnd",
];

struct Frame {
    lex: Lexer,
    import: bool,
    /// The file's canonical path, for finding cycles.
    canonical: Option<PathBuf>,
}

/// Reads a scene's files into its builder.
pub(super) struct Parser {
    pub b: Builder,
    frames: Vec<Frame>,
}

impl Parser {
    /// A parser of the file `file` (already in the builder's sources).
    pub fn new(b: Builder, file: u32) -> Self {
        let text = b.sources.get(file).text.clone();
        let canonical = std::fs::canonicalize(&b.sources.get(file).path).ok();
        Parser { b, frames: vec![Frame { lex: Lexer::new(text, file), import: false, canonical }] }
    }

    fn lex(&mut self) -> &mut Lexer {
        &mut self.frames.last_mut().expect("a directive is read from an open file").lex
    }

    /// Reads every directive of every file.
    pub fn run(&mut self) -> Res<()> {
        while let Some(frame) = self.frames.last_mut() {
            let Some(t) = frame.lex.next()? else {
                let done = self.frames.pop().expect("the loop holds a frame");
                if done.import {
                    self.b.end_import(done.lex.end_place())?;
                }
                continue;
            };
            let at = frame.lex.place(t.start);
            if t.kind != Kind::Word {
                let found = frame.lex.slice(&t).chars().take(40).collect::<String>();
                return fail(at, format!("expected a directive such as Shape or WorldBegin, found `{found}`"));
            }
            let name = frame.lex.slice(&t).to_owned();
            self.directive(&name, at)?;
        }
        Ok(())
    }

    /// The next token of the current file, which must exist: `what` says what was expected.
    fn token(&mut self, what: &str) -> Res<Token> {
        match self.lex().next()? {
            Some(t) => Ok(t),
            None => {
                let end = self.lex().end_place();
                fail(end, format!("the file ends where {what} was expected"))
            }
        }
    }

    fn string(&mut self, directive: &str) -> Res<(String, Place)> {
        let t = self.token(&format!("the quoted name after {directive}"))?;
        let at = self.lex().place(t.start);
        if !matches!(t.kind, Kind::Str { .. }) {
            let found = self.lex().slice(&t).to_owned();
            return fail(at, format!("{directive} expects a quoted string, found `{found}`"));
        }
        Ok((self.lex().string(&t).into_owned(), at))
    }

    /// `N` numbers, bare or in brackets.
    fn numbers<const N: usize>(&mut self, directive: &str) -> Res<[f64; N]> {
        let mut out = [0.0; N];
        let first = self.lex().peek()?;
        let bracketed = first.is_some_and(|t| t.kind == Kind::Open);
        if bracketed {
            self.lex().next()?;
        }
        for (i, v) in out.iter_mut().enumerate() {
            let t = self.token(&format!("number {} of {N} of {directive}", i + 1))?;
            let at = self.lex().place(t.start);
            let word = self.lex().slice(&t).to_owned();
            match word.parse::<f64>() {
                Ok(x) if t.kind == Kind::Word && x.is_finite() && x.abs() <= f32::MAX as f64 => *v = x,
                _ => return fail(at, format!("{directive} takes {N} numbers: number {} is `{word}`", i + 1)),
            }
        }
        if bracketed {
            let t = self.token(&format!("the `]` closing {directive}'s numbers"))?;
            if t.kind != Kind::Close {
                let at = self.lex().place(t.start);
                return fail(at, format!("{directive} takes exactly {N} numbers in its brackets"));
            }
        }
        Ok(out)
    }

    fn params(&mut self) -> Res<Params> {
        parse_params(self.lex())
    }

    fn directive(&mut self, name: &str, at: Place) -> Res<()> {
        let ctm = self.b.gs.ctm;
        match name {
            "Identity" => self.b.set_ctm(at, glam::DMat4::IDENTITY),
            "Translate" => {
                let [x, y, z] = self.numbers::<3>(name)?;
                self.b.set_ctm(at, transform::translate(ctm, DVec3::new(x, y, z)))
            }
            "Scale" => {
                let [x, y, z] = self.numbers::<3>(name)?;
                self.b.set_ctm(at, transform::scale(ctm, DVec3::new(x, y, z)))
            }
            "Rotate" => {
                let [angle, x, y, z] = self.numbers::<4>(name)?;
                match transform::rotate(ctm, angle, DVec3::new(x, y, z)) {
                    Some(m) => self.b.set_ctm(at, m),
                    None => fail(at, "Rotate: the axis is zero"),
                }
            }
            "LookAt" => {
                let v = self.numbers::<9>(name)?;
                let m = transform::look_at(
                    DVec3::new(v[0], v[1], v[2]),
                    DVec3::new(v[3], v[4], v[5]),
                    DVec3::new(v[6], v[7], v[8]),
                )
                .or_else(|e| fail(at, e))?;
                self.b.set_ctm(at, ctm * m)
            }
            "Transform" | "ConcatTransform" => {
                let m = transform::from_pbrt(&self.numbers::<16>(name)?);
                self.b.set_ctm(at, if name == "Transform" { m } else { ctm * m })
            }
            "CoordinateSystem" => {
                let (n, _) = self.string(name)?;
                self.b.named_coordinates.insert(n, ctm);
                Ok(())
            }
            "CoordSysTransform" => {
                let (n, n_at) = self.string(name)?;
                match self.b.named_coordinates.get(&n) {
                    Some(&m) => self.b.set_ctm(at, m),
                    None => self.b.report.skipped(n_at, &format!("coordinate system {n}"), || {
                        format!(
                            "CoordSysTransform: no coordinate system \"{n}\" is defined: the transform is unchanged"
                        )
                    }),
                }
            }
            "TransformTimes" => {
                self.numbers::<2>(name)?;
                self.b.report.ignored(at, "TransformTimes", || "TransformTimes: motion blur is not rendered".into())
            }
            "ActiveTransform" => {
                let t = self.token("StartTime, EndTime or All after ActiveTransform")?;
                let word = self.lex().slice(&t).to_owned();
                self.b.gs.active = match word.as_str() {
                    "StartTime" => Active::Start,
                    "EndTime" => Active::End,
                    "All" => Active::All,
                    _ => {
                        return fail(
                            self.lex().place(t.start),
                            format!("ActiveTransform takes StartTime, EndTime or All, found `{word}`"),
                        );
                    }
                };
                Ok(())
            }
            "ReverseOrientation" => {
                self.b.gs.reverse_orientation = !self.b.gs.reverse_orientation;
                Ok(())
            }
            "AttributeBegin" => self.b.begin(at, Scope::Attribute),
            "AttributeEnd" => self.b.end(at, Scope::Attribute),
            "TransformBegin" => self.b.begin(at, Scope::Transform),
            "TransformEnd" => self.b.end(at, Scope::Transform),
            "WorldBegin" => self.b.world_begin(at),
            "WorldEnd" => Ok(()),
            "Option" => {
                let params = self.params()?;
                self.b.option(at, &params)
            }
            "ColorSpace" => {
                let (space, _) = self.string(name)?;
                if space == "srgb" {
                    return Ok(());
                }
                self.b.report.approximated(at, "color space", || {
                    format!("ColorSpace \"{space}\": colours are read as linear sRGB")
                })
            }
            "Camera" | "Film" | "Sampler" | "Integrator" | "PixelFilter" => {
                let (kind, _) = self.string(name)?;
                let params = self.params()?;
                self.b.option_directive(at, name, &kind, params)
            }
            "Accelerator" => {
                let (kind, _) = self.string(name)?;
                self.params()?;
                self.b.report.ignored(at, "Accelerator", || {
                    format!("Accelerator \"{kind}\": englobe builds its own structure (--accel)")
                })
            }
            "MakeNamedMedium" | "MediumInterface" => {
                let (first, _) = self.string(name)?;
                if name == "MediumInterface" && matches!(self.lex().peek()?, Some(Token { kind: Kind::Str { .. }, .. }))
                {
                    self.string(name)?;
                } else if name == "MakeNamedMedium" {
                    self.params()?;
                }
                self.b.report.skipped(at, "media", || {
                    format!("{name} \"{first}\": participating media are not supported: left out")
                })
            }
            "Attribute" => {
                let (target, _) = self.string(name)?;
                self.params()?;
                self.b.report.skipped(at, &format!("Attribute {target}"), || {
                    format!(
                        "Attribute \"{target}\": default parameters for a kind of directive are not supported: ignored"
                    )
                })
            }
            "Texture" => {
                let (tex, _) = self.string(name)?;
                let (ty, _) = self.string(name)?;
                let (class, _) = self.string(name)?;
                let params = self.params()?;
                self.b.texture(at, &tex, &ty, &class, &params)
            }
            "Material" | "MakeNamedMaterial" | "LightSource" | "AreaLightSource" | "Shape" => {
                let (kind, _) = self.string(name)?;
                let params = self.params()?;
                match name {
                    "Material" => self.b.material(at, &kind, &params),
                    "MakeNamedMaterial" => self.b.make_named_material(at, &kind, &params),
                    "LightSource" => self.b.light_source(at, &kind, &params),
                    "AreaLightSource" => self.b.area_light_source(at, &kind, &params),
                    _ => self.b.shape(at, &kind, &params),
                }
            }
            "NamedMaterial" => {
                let (n, _) = self.string(name)?;
                self.b.named_material(at, &n)
            }
            "ObjectBegin" => {
                let (n, _) = self.string(name)?;
                self.b.object_begin(at, &n)
            }
            "ObjectEnd" => self.b.object_end(at),
            "ObjectInstance" => {
                let (n, _) = self.string(name)?;
                self.b.object_instance(at, &n)
            }
            "Include" | "Import" => {
                let (file, file_at) = self.string(name)?;
                self.include(at, &file, file_at, name == "Import")
            }
            _ => self.unknown(name, at),
        }
    }

    /// An unknown directive: an error under strict, else reported, its arguments skipped up to the
    /// next known directive.
    fn unknown(&mut self, name: &str, at: Place) -> Res<()> {
        let shown: String = name.chars().take(40).collect();
        self.b.report.skipped(at, &format!("directive {shown}"), || {
            format!("unknown directive `{shown}`: it and its arguments are skipped")
        })?;
        while let Some(t) = self.lex().peek()? {
            if t.kind == Kind::Word && DIRECTIVES.contains(&self.lex().slice(&t)) {
                break;
            }
            self.lex().next()?;
        }
        Ok(())
    }

    fn include(&mut self, at: Place, name: &str, name_at: Place, import: bool) -> Res<()> {
        let what = if import { "Import" } else { "Include" };
        if self.frames.len() >= MAX_INCLUDE_DEPTH {
            return fail(name_at, format!("{what} \"{name}\": files nested more than {MAX_INCLUDE_DEPTH} deep"));
        }
        let candidates = self.b.candidates(name_at, name);
        let path = candidates.iter().find(|p| p.is_file()).unwrap_or(&candidates[0]).clone();
        let canonical = std::fs::canonicalize(&path).ok();
        if canonical.is_some() && self.frames.iter().any(|f| f.canonical == canonical) {
            let chain: Vec<String> =
                self.frames.iter().map(|f| self.b.sources.get(f.lex.file()).name.clone()).collect();
            return fail(
                name_at,
                format!("{what} \"{name}\": an include cycle ({} -> {})", chain.join(" -> "), path.display()),
            );
        }
        let text = read_text(&path).map_err(|e| {
            let tried: Vec<String> = candidates.iter().map(|p| p.display().to_string()).collect();
            Fail::At(name_at, format!("{what} \"{name}\": cannot read it (looked for {}): {e}", tried.join(" and ")))
        })?;
        if self.b.sources.total_bytes() + text.len() as u64 > MAX_PBRT_TOTAL_BYTES {
            return fail(
                name_at,
                format!("{what} \"{name}\": the scene's files add up to more than {MAX_PBRT_TOTAL_BYTES} bytes"),
            );
        }
        if import {
            self.b.begin(at, Scope::Import)?;
        }
        let id = self.b.sources.add(path.display().to_string(), path, text, Some(name_at));
        let text = self.b.sources.get(id).text.clone();
        self.frames.push(Frame { lex: Lexer::new(text, id), import, canonical });
        Ok(())
    }
}

impl Builder {
    /// pbrt-v4's `Option "type name" value`: the seed is used, the rest reported.
    fn option(&mut self, at: Place, params: &Params) -> Res<()> {
        if let Some(seed) = params.integer("seed")? {
            self.option_seed = Some(seed as u64);
        }
        if params.is_empty() {
            return fail(at, "Option takes one parameter, such as \"integer seed\" 7");
        }
        for p in params.unused() {
            let shown = p.shown();
            self.report
                .skipped(p.at, &format!("Option {}", p.name), || format!("Option {shown} is not supported: ignored"))?;
        }
        Ok(())
    }
}
