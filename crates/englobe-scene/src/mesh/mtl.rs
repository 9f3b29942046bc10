//! MTL material libraries: englobe's line-by-line check of what `tobj` will parse (it panicked on
//! `Kd 0.5 0.5` up to version 4.0.4, and reports other mistakes without a line), which also
//! reads the texture statements with their options ([`super::mtl_map`]) and colours in every
//! form ([`super::mtl_color`]), and the mapping of MTL's
//! parameters onto englobe's materials ([`super::mtl_material`]).

use std::collections::HashMap;
use std::path::Path;

use super::error::{MeshErrorKind, MeshFileError};
use super::mtl_color::{MtlColor, parse_color};
use super::mtl_map::{MapStatement, parse_map};

/// The texture statements of each material of a library, by material name, with their keywords.
pub(super) type MtlMaps = HashMap<String, Vec<(String, MapStatement)>>;

/// What [`scan`] makes of a library: its texture statements, its text in the forms `tobj` reads,
/// and what it could not use.
pub(super) struct MtlScan {
    /// Texture statements by material.
    pub maps: MtlMaps,
    /// The library with every colour statement written `K r g b` (see [`super::mtl_color`]),
    /// `d -halo f` as `d f`, and the statements englobe cannot use made comments; one line for
    /// each line of the file, so line numbers stay.
    pub text: String,
    /// One line for each statement read differently from what it says, naming its line.
    pub warnings: Vec<String>,
}

/// The texture statements englobe reads (and those it reads only to check them).
const MAP_KEYWORDS: &[&str] = &[
    "map_Ka", "map_Kd", "map_Ks", "map_Ke", "map_Ns", "map_ns", "map_NS", "map_d", "map_Bump", "map_bump", "bump",
    "norm", "disp", "decal", "refl", "map_Pr", "map_Pm",
];

/// Checks the MTL text `text` of `path` statement by statement, refusing what `tobj` would fail
/// or panic on, and returns the texture statements of each material with the text for `tobj`.
pub(super) fn scan(path: &Path, text: &str) -> Result<MtlScan, MeshFileError> {
    let mut out = MtlScan { maps: MtlMaps::new(), text: String::with_capacity(text.len()), warnings: Vec::new() };
    let mut current: Option<String> = None;
    for (index, raw) in text.lines().enumerate() {
        let err = |kind| MeshFileError::line(path, index + 1, kind);
        let line = raw.trim();
        let mut words = raw.split_whitespace();
        let Some(keyword) = words.next() else {
            out.text.push('\n');
            continue;
        };
        let rest = line.get(keyword.len()..).unwrap_or("").trim();
        let mut rewritten: Option<String> = None;
        match keyword {
            "newmtl" if rest.is_empty() => {
                return Err(err(MeshErrorKind::Arity { keyword: keyword.into(), expected: "a name", found: 0 }));
            }
            "newmtl" => current = Some(rest.to_owned()),
            "Ka" | "Kd" | "Ks" | "Ke" | "Tf" => {
                let color =
                    parse_color(rest).map_err(|e| err(MeshErrorKind::Malformed(format!("`{keyword}`: {e}"))))?;
                rewritten = Some(match color {
                    MtlColor::Rgb(c) => format!("{keyword} {} {} {}", c.x, c.y, c.z),
                    MtlColor::Spectral { file, .. } => {
                        out.warnings.push(format!(
                            "{}:{}: `{keyword} spectral {file}`: spectral curves are not read; the colour keeps its default",
                            path.display(),
                            index + 1
                        ));
                        format!("# {keyword} spectral")
                    }
                });
            }
            "d" if rest.starts_with("-halo") => {
                let factor = rest["-halo".len()..].trim();
                out.warnings.push(format!(
                    "{}:{}: `d -halo {factor}`: the dissolve is read as constant (the halo's dependence on the angle is not modelled)",
                    path.display(),
                    index + 1
                ));
                words = factor.split_whitespace();
                rewritten = Some(format!("d {factor}"));
                check_number(&mut words, "d", &err)?;
            }
            "Ns" | "Ni" | "d" | "Tr" | "sharpness" => check_number(&mut words, keyword, &err)?,
            "illum" => {
                let word = words.next().unwrap_or("");
                if word.parse::<u8>().is_err() {
                    return Err(err(MeshErrorKind::BadNumber {
                        token: word.to_owned(),
                        expected: "an illumination model number from 0 to 255",
                    }));
                }
            }
            k if MAP_KEYWORDS.contains(&k) => {
                let map = parse_map(rest).map_err(|e| err(MeshErrorKind::Malformed(format!("`{keyword}` {e}"))))?;
                if let Some(name) = &current {
                    out.maps.entry(name.clone()).or_default().push((keyword.to_owned(), map));
                }
            }
            _ => {}
        }
        out.text.push_str(rewritten.as_deref().unwrap_or(raw));
        out.text.push('\n');
    }
    Ok(out)
}

/// Checks that the next word is a finite number, the value of statement `keyword`.
fn check_number<'a>(
    words: &mut impl Iterator<Item = &'a str>,
    keyword: &str,
    err: &impl Fn(MeshErrorKind) -> MeshFileError,
) -> Result<(), MeshFileError> {
    let Some(word) = words.next() else {
        return Err(err(MeshErrorKind::Arity { keyword: keyword.into(), expected: "a number", found: 0 }));
    };
    match word.parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(()),
        Ok(_) => Err(err(MeshErrorKind::NonFinite { what: format!("`{keyword}`"), value: word.to_owned() })),
        Err(_) => Err(err(MeshErrorKind::BadNumber { token: word.to_owned(), expected: "a number" })),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(text: &str) -> Result<MtlMaps, MeshFileError> {
        scan(Path::new("t.mtl"), text).map(|s| s.maps)
    }

    #[test]
    fn a_colour_with_two_numbers_is_refused_at_its_line() {
        let e = check("newmtl a\nKd 0.5 0.5\n").unwrap_err();
        assert_eq!(e.line_number(), Some(2));
        assert!(e.to_string().contains("`Kd`: expected a colour") && e.to_string().contains("found two"), "{e}");
    }

    #[test]
    fn every_form_is_rewritten_for_tobj_line_for_line() {
        let s = scan(
            Path::new("t.mtl"),
            "newmtl a\nKd 0.5\nKs xyz 0.5\n\nKa spectral r.rfl 2\nTf 0.1 0.2 0.3 # glass\nd -halo 0.4\nsharpness 60\n",
        )
        .unwrap();
        let lines: Vec<&str> = s.text.lines().collect();
        assert_eq!(lines.len(), 8);
        assert_eq!(
            (lines[1], lines[3], lines[4], lines[5], lines[6]),
            ("Kd 0.5 0.5 0.5", "", "# Ka spectral", "Tf 0.1 0.2 0.3", "d 0.4")
        );
        assert!(lines[2].starts_with("Ks 0.60"), "{}", lines[2]);
        assert_eq!(s.warnings.len(), 2, "{:?}", s.warnings);
        assert!(s.warnings[0].starts_with("t.mtl:5: `Ka spectral r.rfl`"), "{:?}", s.warnings);
        assert!(s.warnings[1].starts_with("t.mtl:7: `d -halo 0.4`"), "{:?}", s.warnings);
        let e = check("newmtl a\nd -halo\n").unwrap_err();
        assert_eq!(e.line_number(), Some(2), "{e}");
    }

    #[test]
    fn bad_values_are_refused() {
        for (text, line) in [
            ("newmtl\n", 1),
            ("newmtl a\nNs x\n", 2),
            ("newmtl a\n\nd nan\n", 3),
            ("illum 300\n", 1),
            ("map_Kd   \n", 1),
            ("Ke 1 2 inf\n", 1),
        ] {
            assert_eq!(check(text).unwrap_err().line_number(), Some(line), "{text:?}");
        }
        check("newmtl a\nKa 0.63 0.065 0.05 # Red\nTr 0.25\nillum 4\n").unwrap();
    }

    #[test]
    fn texture_statements_are_kept_by_material() {
        let maps = check("newmtl a\nmap_Kd -s 2 2 a.png\nnewmtl b\r\nbump -bm 0.5 b h.png\nnorm n.png\n").unwrap();
        assert_eq!(maps["a"][0].0, "map_Kd");
        assert_eq!(maps["a"][0].1.options.s, [2.0, 2.0, 1.0]);
        assert_eq!((maps["b"][0].1.file.as_str(), maps["b"][0].1.options.bm), ("b h.png", 0.5));
        assert_eq!(maps["b"][1].0, "norm");
        let e = check("newmtl a\n\nmap_d -imfchan x a.png\n").unwrap_err();
        assert_eq!(e.line_number(), Some(3));
        assert!(e.to_string().contains("-imfchan"), "{e}");
    }
}
