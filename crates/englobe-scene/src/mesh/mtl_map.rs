//! MTL texture statements (`map_Kd`, `map_Ks`, `map_Ke`, `map_d`, `bump`, `map_Bump`, `norm`,
//! ...) with their options, read in every form the MTL specification allows (Wavefront, "MTL
//! material format", Advanced Visualizer 4.2 manual, appendix B1; the options tinyobjloader
//! parses): options in any order, repeated ones overriding, `-o`, `-s` and `-t` with one to three
//! numbers (`u [v [w]]`), `-mm` with one or two (`base [gain]`), and the file name the rest of
//! the line, spaces included.

/// The options of one texture statement, with the specification's defaults.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct MapOptions {
    /// `-blendu on|off` (default on): blending across `u`; englobe always filters.
    pub blendu: bool,
    /// `-blendv on|off` (default on).
    pub blendv: bool,
    /// `-bm mult` (default 1): bump multiplier.
    pub bm: f32,
    /// `-boost value` (default 0): mip-map sharpening; englobe has no mip-maps.
    pub boost: f32,
    /// `-cc on|off` (default off): colour correction, not applied.
    pub cc: bool,
    /// `-clamp on|off` (default off): clamp coordinates to `0..1` instead of repeating.
    pub clamp: bool,
    /// `-imfchan r|g|b|m|l|z`: channel of a scalar or bump texture (none given: the statement's
    /// default).
    pub imfchan: Option<char>,
    /// `-mm base gain` (default 0 1): values become `base + gain * value`.
    pub mm: [f32; 2],
    /// `-o u [v [w]]` (default 0 0 0): origin offset.
    pub o: [f32; 3],
    /// `-s u [v [w]]` (default 1 1 1): scale.
    pub s: [f32; 3],
    /// `-t u [v [w]]` (default 0 0 0): turbulence, not applied.
    pub t: [f32; 3],
    /// `-texres value`: resolution to resample to, not applied.
    pub texres: Option<u32>,
    /// `-type sphere|cube_...` (reflection maps).
    pub kind: Option<String>,
    /// `-colorspace NAME` (tinyobjloader's extension): `sRGB` or `linear`.
    pub colorspace: Option<String>,
}

impl Default for MapOptions {
    fn default() -> Self {
        MapOptions {
            blendu: true,
            blendv: true,
            bm: 1.0,
            boost: 0.0,
            cc: false,
            clamp: false,
            imfchan: None,
            mm: [0.0, 1.0],
            o: [0.0; 3],
            s: [1.0; 3],
            t: [0.0; 3],
            texres: None,
            kind: None,
            colorspace: None,
        }
    }
}

/// A texture statement: its options and its file name.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct MapStatement {
    pub options: MapOptions,
    pub file: String,
}

/// The words of `text` with their byte offsets.
fn words(text: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, c) in text.char_indices() {
        match (c.is_whitespace(), start) {
            (true, Some(s)) => {
                out.push((s, &text[s..i]));
                start = None;
            }
            (false, None) => start = Some(i),
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push((s, &text[s..]));
    }
    out
}

fn number(word: Option<&(usize, &str)>, option: &str) -> Result<f32, String> {
    let Some((_, w)) = word else { return Err(format!("`{option}` expects a number, found the end of the line")) };
    match w.parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("`{option}` expects a number, found `{w}`")),
    }
}

fn on_off(word: Option<&(usize, &str)>, option: &str) -> Result<bool, String> {
    match word.map(|w| w.1) {
        Some("on") => Ok(true),
        Some("off") => Ok(false),
        Some(w) => Err(format!("`{option}` expects `on` or `off`, found `{w}`")),
        None => Err(format!("`{option}` expects `on` or `off`, found the end of the line")),
    }
}

/// Parses the rest of a texture statement (what follows the keyword).
pub(super) fn parse_map(rest: &str) -> Result<MapStatement, String> {
    let words = words(rest);
    let mut o = MapOptions::default();
    let mut i = 0;
    // Up to `most` numbers from word `i` on, at least one.
    let numbers = |i: &mut usize, most: usize, option: &str| -> Result<Vec<f32>, String> {
        let mut out = vec![number(words.get(*i), option)?];
        *i += 1;
        while out.len() < most {
            match words.get(*i).and_then(|w| w.1.parse::<f32>().ok()).filter(|v| v.is_finite()) {
                // A number is an argument only if a file name is still left after it.
                Some(v) if *i + 1 < words.len() => {
                    out.push(v);
                    *i += 1;
                }
                _ => break,
            }
        }
        Ok(out)
    };
    let triple =
        |v: Vec<f32>, default: f32| -> [f32; 3] { std::array::from_fn(|k| v.get(k).copied().unwrap_or(default)) };
    while let Some(&(_, word)) = words.get(i) {
        if !word.starts_with('-') || word.len() < 2 || word[1..].parse::<f32>().is_ok() {
            break;
        }
        i += 1;
        match word {
            "-blendu" => o.blendu = on_off(words.get(i), word)?,
            "-blendv" => o.blendv = on_off(words.get(i), word)?,
            "-cc" => o.cc = on_off(words.get(i), word)?,
            "-clamp" => o.clamp = on_off(words.get(i), word)?,
            "-bm" => o.bm = number(words.get(i), word)?,
            "-boost" => o.boost = number(words.get(i), word)?,
            "-texres" => {
                let v = number(words.get(i), word)?;
                if v < 1.0 || v.fract() != 0.0 {
                    return Err(format!("`-texres` expects a whole number of texels, found `{v}`"));
                }
                o.texres = Some(v as u32);
            }
            "-mm" => {
                let v = numbers(&mut i, 2, word)?;
                o.mm = [v[0], v.get(1).copied().unwrap_or(1.0)];
                continue;
            }
            "-o" => {
                o.o = triple(numbers(&mut i, 3, word)?, 0.0);
                continue;
            }
            "-s" => {
                o.s = triple(numbers(&mut i, 3, word)?, 1.0);
                continue;
            }
            "-t" => {
                o.t = triple(numbers(&mut i, 3, word)?, 0.0);
                continue;
            }
            "-imfchan" => match words.get(i).map(|w| w.1) {
                Some(c @ ("r" | "g" | "b" | "m" | "l" | "z")) => o.imfchan = c.chars().next(),
                other => {
                    return Err(format!("`-imfchan` expects one of r, g, b, m, l, z, found `{}`", other.unwrap_or("")));
                }
            },
            "-type" => match words.get(i).map(|w| w.1) {
                Some(
                    t @ ("sphere" | "cube_top" | "cube_bottom" | "cube_front" | "cube_back" | "cube_left"
                    | "cube_right"),
                ) => o.kind = Some(t.to_owned()),
                other => {
                    return Err(format!(
                        "`-type` expects sphere or cube_top..cube_right, found `{}`",
                        other.unwrap_or("")
                    ));
                }
            },
            "-colorspace" => match words.get(i) {
                Some(w) => o.colorspace = Some(w.1.to_owned()),
                None => return Err("`-colorspace` expects a name".into()),
            },
            _ => return Err(format!("unknown texture option `{word}`")),
        }
        i += 1;
    }
    let file = words.get(i).map_or("", |&(at, _)| rest[at..].trim());
    if file.is_empty() {
        return Err("expects a texture file name".into());
    }
    Ok(MapStatement { options: o, file: file.to_owned() })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ok(text: &str) -> MapStatement {
        parse_map(text).unwrap_or_else(|e| panic!("{text:?}: {e}"))
    }

    #[test]
    fn a_bare_file_name_keeps_every_default() {
        let m = ok("wood.png");
        assert_eq!((m.file.as_str(), &m.options), ("wood.png", &MapOptions::default()));
        assert_eq!(ok("  my wood texture.png ").file, "my wood texture.png", "names may hold spaces");
    }

    #[test]
    fn offsets_scales_and_turbulence_take_one_to_three_numbers() {
        assert_eq!(ok("-o 0.5 t.png").options.o, [0.5, 0.0, 0.0]);
        assert_eq!(ok("-o 0.5 0.25 t.png").options.o, [0.5, 0.25, 0.0]);
        assert_eq!(ok("-o 0.5 0.25 2 t.png").options.o, [0.5, 0.25, 2.0]);
        assert_eq!(ok("-s 2 t.png").options.s, [2.0, 1.0, 1.0], "missing scales default to 1");
        assert_eq!(ok("-t 0.1 0.2 0.3 t.png").options.t, [0.1, 0.2, 0.3]);
        // At most three: a fourth number is the file name; negative numbers are numbers.
        assert_eq!(ok("-s 1 1 1").file, "1", "the last number left is the file name");
        let m = ok("-s 1 2 3 4");
        assert_eq!((m.options.s, m.file.as_str()), ([1.0, 2.0, 3.0], "4"));
        assert_eq!(ok("-o -0.5 -1 t.png").options.o, [-0.5, -1.0, 0.0]);
        // A number just before the end is the file, not an argument.
        assert_eq!(ok("-o 1 2").file, "2");
    }

    #[test]
    fn switches_channels_and_the_rest() {
        let m =
            ok("-blendu off -blendv off -cc on -clamp on -bm 0.2 -boost 1.5 -texres 512 -imfchan r -mm 0.1 2 h.png");
        let o = &m.options;
        assert!(!o.blendu && !o.blendv && o.cc && o.clamp);
        assert_eq!((o.bm, o.boost, o.texres, o.imfchan, o.mm), (0.2, 1.5, Some(512), Some('r'), [0.1, 2.0]));
        assert_eq!(ok("-mm 0.5 t.png").options.mm, [0.5, 1.0], "gain defaults to 1");
        assert_eq!(ok("-type sphere r.png").options.kind.as_deref(), Some("sphere"));
        assert_eq!(ok("-colorspace linear n.png").options.colorspace.as_deref(), Some("linear"));
        // Options in any order, the last of a repeated one winning.
        let m = ok("-clamp on -s 2 2 -clamp off t.png");
        assert_eq!((m.options.clamp, m.options.s), (false, [2.0, 2.0, 1.0]));
    }

    #[test]
    fn malformed_statements_say_what_was_expected() {
        for (text, expected) in [
            ("-bm", "expects a number"),
            ("-bm x t.png", "expects a number, found `x`"),
            ("-clamp maybe t.png", "`on` or `off`"),
            ("-imfchan q t.png", "r, g, b, m, l, z"),
            ("-texres 0.5 t.png", "whole number"),
            ("-o", "expects a number"),
            ("-frobnicate t.png", "unknown texture option"),
            ("-clamp on", "expects a texture file name"),
            ("", "expects a texture file name"),
        ] {
            let e = parse_map(text).unwrap_err();
            assert!(e.contains(expected), "{text:?}: {e}");
        }
    }
}
