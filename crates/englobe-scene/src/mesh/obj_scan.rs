//! englobe's own pass over an OBJ file before `tobj` reads it: every statement `tobj` would act
//! on is checked line by line, so that a bad file is refused with its line number and a clear
//! message instead of `tobj`'s bare error kinds (or its arithmetic on bad indices).
//!
//! The checks follow what `tobj` 4 accepts: `v x y z [w | r g b]`, `vt u v [w]`, `vn x y z`,
//! faces of `v`, `v/vt`, `v//vn` or `v/vt/vn` references counted from 1, or back from the last
//! element defined when negative. Stricter on one point: a reference must name an element defined
//! before its line (OBJ's own rule), which is what makes negative references meaningful.

use std::path::Path;

use super::error::{MeshErrorKind, MeshFileError};

/// What the scan learnt about a valid file.
#[derive(Debug, Default)]
pub(super) struct ObjScan {
    /// `v` statements.
    pub positions: u64,
    /// Faces with three or more vertices.
    pub faces: u64,
    /// Faces with one or two vertices (points and lines written as `f`), which are skipped.
    pub short_faces: u64,
    /// `l` (line) and `p` (point) statements, which are skipped.
    pub lines_and_points: u64,
    /// 0-based indices of the lines that hold `l` statements (hidden from `tobj`, which would
    /// turn a polyline of three points or more into a polygon).
    pub polyline_lines: Vec<usize>,
    /// Material names given to `usemtl`, in first-use order.
    pub used_materials: Vec<String>,
    /// Library names given to `mtllib`.
    pub libraries: Vec<String>,
    /// Warnings to pass on.
    pub warnings: Vec<String>,
}

/// A reference to an element that does not exist, kept until the end of the scan: references
/// to texture coordinates or normals in a file that defines none at all are ignored (as `tobj`
/// does), any other is an error.
struct Pending {
    line: usize,
    token: String,
    defined: u64,
}

/// Checks `text`, the content of the OBJ file `path`.
pub(super) fn scan(path: &Path, text: &str) -> Result<ObjScan, MeshFileError> {
    let mut s = ObjScan::default();
    let (mut texcoords, mut normals) = (0u64, 0u64);
    let (mut bad_texcoord, mut bad_normal): (Option<Pending>, Option<Pending>) = (None, None);
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let err = |kind| MeshFileError::line(path, line, kind);
        let mut words = raw.split_whitespace();
        let Some(keyword) = words.next() else { continue };
        match keyword {
            "v" => {
                let mut values = [0f32; 7];
                let mut n = 0;
                for word in words {
                    if n == values.len() {
                        n += 1;
                        break;
                    }
                    values[n] = number(word).map_err(err)?;
                    n += 1;
                }
                let expected = "3 coordinates (x y z), then optionally w or r g b";
                if !(n == 3 || n == 4 || n == 6) {
                    return Err(err(MeshErrorKind::Arity { keyword: "v".into(), expected, found: n }));
                }
                finite("vertex coordinate", &values[..n]).map_err(err)?;
                if n == 4 {
                    let w = values[3];
                    let scaled = [values[0] / w, values[1] / w, values[2] / w];
                    if w == 0.0 || scaled.iter().any(|c| !c.is_finite()) {
                        return Err(err(MeshErrorKind::NonFinite {
                            what: "vertex coordinate divided by its weight w".into(),
                            value: format!("w = {w}"),
                        }));
                    }
                }
                s.positions += 1;
            }
            "vt" | "vn" => {
                let need = if keyword == "vt" { 2 } else { 3 };
                let mut values = [0f32; 3];
                let mut n = 0;
                for word in words.take(need) {
                    values[n] = number(word).map_err(err)?;
                    n += 1;
                }
                if n < need {
                    let expected = if need == 2 { "2 texture coordinates (u v)" } else { "3 normal components" };
                    return Err(err(MeshErrorKind::Arity { keyword: keyword.into(), expected, found: n }));
                }
                let what = if need == 2 { "texture coordinate" } else { "normal component" };
                finite(what, &values[..n]).map_err(err)?;
                if need == 2 { texcoords += 1 } else { normals += 1 }
            }
            "f" => {
                let mut count = 0u64;
                for word in words {
                    let mut parts = word.split('/');
                    let v = parts.next().unwrap_or("");
                    let (vt, vn) = (parts.next().unwrap_or(""), parts.next().unwrap_or(""));
                    if parts.next().is_some() || v.is_empty() {
                        return Err(err(MeshErrorKind::Malformed(format!(
                            "malformed face vertex `{word}`: expected v, v/vt, v//vn or v/vt/vn"
                        ))));
                    }
                    reference(v, "vertex", s.positions).map_err(err)?;
                    for (part, what, defined, pending) in [
                        (vt, "texture coordinate", texcoords, &mut bad_texcoord),
                        (vn, "normal", normals, &mut bad_normal),
                    ] {
                        if part.is_empty() {
                            continue;
                        }
                        match reference(part, what, defined) {
                            Ok(()) => {}
                            Err(MeshErrorKind::IndexOutOfRange { .. }) if pending.is_none() => {
                                *pending = Some(Pending { line, token: part.to_owned(), defined });
                            }
                            Err(MeshErrorKind::IndexOutOfRange { .. }) => {}
                            Err(e) => return Err(err(e)),
                        }
                    }
                    count += 1;
                }
                match count {
                    0 => {
                        return Err(err(MeshErrorKind::Arity {
                            keyword: "f".into(),
                            expected: "at least 3 vertices",
                            found: 0,
                        }));
                    }
                    1 | 2 => s.short_faces += 1,
                    _ => s.faces += 1,
                }
            }
            "l" => {
                s.lines_and_points += 1;
                s.polyline_lines.push(index);
            }
            "p" => s.lines_and_points += 1,
            "usemtl" | "mtllib" => {
                // `tobj` takes the name after the first space, whole: names may hold spaces.
                let name = raw.split_once(' ').map_or("", |(_, rest)| rest.trim());
                if name.is_empty() {
                    return Err(err(MeshErrorKind::Arity {
                        keyword: keyword.into(),
                        expected: "a name after a space",
                        found: 0,
                    }));
                }
                let list = if keyword == "usemtl" { &mut s.used_materials } else { &mut s.libraries };
                if !list.iter().any(|n| n == name) {
                    list.push(name.to_owned());
                }
            }
            _ => {}
        }
    }
    for (pending, what, defined) in [(bad_texcoord, "texture coordinate", texcoords), (bad_normal, "normal", normals)] {
        let Some(p) = pending else { continue };
        if defined == 0 {
            s.warnings.push(format!("faces refer to {what}s but the file defines none; the references are ignored"));
        } else {
            return Err(MeshFileError::line(
                path,
                p.line,
                MeshErrorKind::IndexOutOfRange {
                    what,
                    index: p.token,
                    available: p.defined,
                    context: " before this line",
                },
            ));
        }
    }
    Ok(s)
}

/// A number as `tobj` reads it (Rust's `f32` syntax).
fn number(word: &str) -> Result<f32, MeshErrorKind> {
    word.parse().map_err(|_| MeshErrorKind::BadNumber { token: word.to_owned(), expected: "a number" })
}

fn finite(what: &str, values: &[f32]) -> Result<(), MeshErrorKind> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(v) => Err(MeshErrorKind::NonFinite { what: what.to_owned(), value: v.to_string() }),
        None => Ok(()),
    }
}

/// Checks one 1-based or negative reference against the `defined` elements before the line.
fn reference(word: &str, what: &'static str, defined: u64) -> Result<(), MeshErrorKind> {
    let out_of_range =
        |context| MeshErrorKind::IndexOutOfRange { what, index: word.to_owned(), available: defined, context };
    let Ok(i) = word.parse::<i64>() else {
        let digits = word.strip_prefix('-').unwrap_or(word);
        return Err(if !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) {
            out_of_range(" before this line (the index does not even fit 64 bits)")
        } else {
            MeshErrorKind::BadNumber { token: word.to_owned(), expected: "an integer index" }
        });
    };
    if i == 0 {
        return Err(out_of_range(" before this line; OBJ indices start at 1 (or count back from -1)"));
    }
    let fits = if i > 0 { i as u64 <= defined } else { i.unsigned_abs() <= defined };
    if fits { Ok(()) } else { Err(out_of_range(" before this line")) }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(text: &str) -> Result<ObjScan, MeshFileError> {
        scan(Path::new("t.obj"), text)
    }

    #[test]
    fn references_are_checked_against_what_came_before() {
        let ok = check("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf -3 -2 -1\nvt 0 0\nf 1/1 2/1 3/-1\n").unwrap();
        assert_eq!((ok.positions, ok.faces), (3, 3));
        let e = check("v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n").unwrap_err();
        assert_eq!(e.line_number(), Some(3));
        assert!(matches!(e.kind, MeshErrorKind::IndexOutOfRange { what: "vertex", available: 2, .. }), "{e}");
    }

    #[test]
    fn missing_texture_coordinates_everywhere_are_only_a_warning() {
        let s = check("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/2 3/3\n").unwrap();
        assert_eq!(s.warnings.len(), 1);
        let e = check("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/3\n").unwrap_err();
        assert_eq!(e.line_number(), Some(5));
    }

    #[test]
    fn short_faces_lines_and_points_are_counted() {
        let s = check("v 0 0 0\nv 1 0 0\nf 1 2\nl 1 2\np 1\n").unwrap();
        assert_eq!((s.faces, s.short_faces, s.lines_and_points), (0, 1, 2));
        assert_eq!(s.polyline_lines, vec![3]);
    }

    #[test]
    fn malformed_statements_name_their_line() {
        for (text, line) in [
            ("v 1 2 3\nf 1/2/3/4 1 1\n", 2),
            ("v 1 2 3 0\n", 1),
            ("v 1 2 3 4 5\n", 1),
            ("\n\nvn 1 x 0\n", 3),
            ("usemtl\n", 1),
            ("f\n", 1),
            ("v 1 2 3\nf /1 1 1\n", 2),
        ] {
            let e = check(text).unwrap_err();
            assert_eq!(e.line_number(), Some(line), "{text:?}: {e}");
        }
    }
}
