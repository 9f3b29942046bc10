//! MTL material libraries: englobe's line-by-line check of what `tobj` will parse (it panicked on
//! `Kd 0.5 0.5` up to version 4.0.4, and reports other mistakes without a line), which also
//! reads the texture statements with their options ([`super::mtl_map`]), and the mapping of MTL's
//! parameters onto englobe's materials ([`super::mtl_material`]).

use std::collections::HashMap;
use std::path::Path;

use super::error::{MeshErrorKind, MeshFileError};
use super::mtl_map::{MapStatement, parse_map};

/// The texture statements of each material of a library, by material name, with their keywords.
pub(super) type MtlMaps = HashMap<String, Vec<(String, MapStatement)>>;

/// The texture statements englobe reads (and those it reads only to check them).
const MAP_KEYWORDS: &[&str] = &[
    "map_Ka", "map_Kd", "map_Ks", "map_Ke", "map_Ns", "map_ns", "map_NS", "map_d", "map_Bump", "map_bump", "bump",
    "norm", "disp", "decal", "refl", "map_Pr", "map_Pm",
];

/// Checks the MTL text `text` of `path` statement by statement, refusing what `tobj` would fail
/// or panic on, and returns the texture statements of each material.
pub(super) fn scan(path: &Path, text: &str) -> Result<MtlMaps, MeshFileError> {
    let mut maps = MtlMaps::new();
    let mut current: Option<String> = None;
    for (index, raw) in text.lines().enumerate() {
        let err = |kind| MeshFileError::line(path, index + 1, kind);
        let line = raw.trim();
        let mut words = raw.split_whitespace();
        let Some(keyword) = words.next() else { continue };
        let rest = line.get(keyword.len()..).unwrap_or("").trim();
        match keyword {
            "newmtl" if rest.is_empty() => {
                return Err(err(MeshErrorKind::Arity { keyword: keyword.into(), expected: "a name", found: 0 }));
            }
            "newmtl" => current = Some(rest.to_owned()),
            "Ka" | "Kd" | "Ks" | "Ke" => {
                // Up to three numbers; `tobj` ignores what follows (often a comment).
                let mut n = 0;
                for word in words.take(3) {
                    let v: f32 = word.parse().map_err(|_| {
                        err(MeshErrorKind::BadNumber {
                            token: word.to_owned(),
                            expected: "a number (colours are written `r g b`)",
                        })
                    })?;
                    if !v.is_finite() {
                        return Err(err(MeshErrorKind::NonFinite {
                            what: format!("the colour `{keyword}`"),
                            value: word.to_owned(),
                        }));
                    }
                    n += 1;
                }
                if n < 3 {
                    return Err(err(MeshErrorKind::Arity {
                        keyword: keyword.into(),
                        expected: "three numbers (r g b)",
                        found: n,
                    }));
                }
            }
            "Ns" | "Ni" | "d" | "Tr" => {
                let Some(word) = words.next() else {
                    return Err(err(MeshErrorKind::Arity { keyword: keyword.into(), expected: "a number", found: 0 }));
                };
                match word.parse::<f32>() {
                    Ok(v) if v.is_finite() => {}
                    Ok(_) => {
                        return Err(err(MeshErrorKind::NonFinite {
                            what: format!("`{keyword}`"),
                            value: word.to_owned(),
                        }));
                    }
                    Err(_) => {
                        return Err(err(MeshErrorKind::BadNumber { token: word.to_owned(), expected: "a number" }));
                    }
                }
            }
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
                    maps.entry(name.clone()).or_default().push((keyword.to_owned(), map));
                }
            }
            _ => {}
        }
    }
    Ok(maps)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(text: &str) -> Result<MtlMaps, MeshFileError> {
        scan(Path::new("t.mtl"), text)
    }

    #[test]
    fn a_colour_with_two_numbers_is_refused_at_its_line() {
        let e = check("newmtl a\nKd 0.5 0.5\n").unwrap_err();
        assert_eq!(e.line_number(), Some(2));
        assert!(matches!(e.kind, MeshErrorKind::Arity { found: 2, .. }), "{e}");
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
