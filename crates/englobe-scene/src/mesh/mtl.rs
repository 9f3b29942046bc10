//! MTL material libraries: englobe's line-by-line check of what `tobj` will parse (it panicked on
//! `Kd 0.5 0.5` up to version 4.0.4, and reports other mistakes without a line), and the mapping
//! of MTL's parameters onto englobe's Whitted materials.
//!
//! The mapping, documented in `docs/scene-format.md`:
//!
//! | MTL | englobe |
//! |---|---|
//! | `Kd` | `diffuse` |
//! | `Ks` | `specular` (none under `illum` 0 and 1, which have no highlight) |
//! | `Ns` | `shininess` |
//! | `Ni` | `ior` (values not above 0 keep the default) |
//! | `d`, or `Tr` = 1 - `d` when `d` is absent | `transparency = 1 - d` |
//! | `Ke` | `emission` |
//! | `illum` 3 to 7 (ray-traced reflection) | `reflectivity` = largest component of `Ks`, at most `1 - transparency` |

use std::path::Path;

use englobe::Vec3;

use super::error::{MeshErrorKind, MeshFileError};
use crate::model::Material;

/// Checks the MTL text `text` of `path` statement by statement, refusing what `tobj` would fail
/// or panic on.
pub(super) fn scan(path: &Path, text: &str) -> Result<(), MeshFileError> {
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
            "map_Ka" | "map_Kd" | "map_Ks" | "map_Bump" | "map_bump" | "map_Ns" | "map_ns" | "map_NS" | "bump"
            | "map_d"
                if rest.is_empty() =>
            {
                return Err(err(MeshErrorKind::Arity {
                    keyword: keyword.into(),
                    expected: "a texture file name",
                    found: 0,
                }));
            }
            _ => {}
        }
    }
    Ok(())
}

/// englobe's material for a checked MTL material.
pub(super) fn to_material(m: &tobj::Material) -> Material {
    let base = Material::default();
    let color = |c: Option<[f32; 3]>, default: Vec3| c.map_or(default, |c| Vec3::from(c).max(Vec3::ZERO));
    let illum = m.illumination_model;
    let specular = match illum {
        Some(0) | Some(1) => Vec3::ZERO,
        _ => color(m.specular, base.specular),
    };
    // `Tr` is what `tobj` keeps as an unknown parameter; `scan` checked that it is a number.
    let tr = m.unknown_param.get("Tr").and_then(|t| t.split_whitespace().next()?.parse::<f32>().ok());
    let dissolve = m.dissolve.or(tr.map(|t| 1.0 - t)).unwrap_or(1.0);
    let transparency = (1.0 - dissolve).clamp(0.0, 1.0);
    let reflectivity = match illum {
        Some(3..=7) => specular.max_element().clamp(0.0, 1.0 - transparency),
        _ => 0.0,
    };
    Material {
        diffuse: color(m.diffuse, base.diffuse),
        specular,
        shininess: m.shininess.filter(|s| *s >= 0.0).unwrap_or(base.shininess),
        reflectivity,
        transparency,
        ior: m.optical_density.filter(|n| *n > 0.0).unwrap_or(base.ior),
        emission: color(m.emissive, Vec3::ZERO),
        ..base
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(text: &str) -> Result<(), MeshFileError> {
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
    fn mapping_follows_the_table() {
        let text = "newmtl glass\nKd 0.1 0.2 0.3\nKs 0.9 0.8 0.7\nNs 50\nNi 1.33\nTr 0.25\nillum 7\nKe 0 1 0\n";
        let (mats, _) = tobj::load_mtl_buf(&mut text.as_bytes()).unwrap();
        let m = to_material(&mats[0]);
        assert_eq!(m.diffuse, Vec3::new(0.1, 0.2, 0.3));
        assert_eq!((m.shininess, m.ior, m.transparency), (50.0, 1.33, 0.25));
        assert_eq!(m.reflectivity, 0.75, "Ks 0.9, capped at 1 - transparency");
        assert_eq!(m.emission, Vec3::Y);
        let (mats, _) = tobj::load_mtl_buf(&mut "newmtl m\nKs 1 1 1\nillum 1\nd 1\nTr 0.5\n".as_bytes()).unwrap();
        let m = to_material(&mats[0]);
        assert_eq!((m.specular, m.transparency, m.reflectivity), (Vec3::ZERO, 0.0, 0.0), "d wins over Tr");
    }
}
