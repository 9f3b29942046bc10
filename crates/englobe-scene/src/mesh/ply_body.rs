//! The body of a PLY file, read element by element from a parsed header: ASCII bodies line by
//! line (errors give the line), binary ones value by value in either byte order (errors give the
//! byte offset). Lists are checked against the bytes or values left before they are read.

use std::path::Path;

use englobe::{Vec2, Vec3};

use super::error::{MeshErrorKind, MeshFileError, Position};
use super::ply_header::{Encoding, Header, Property, Scalar};

/// What englobe keeps of a PLY body.
#[derive(Debug, Default)]
pub(super) struct Body {
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<Vec2>>,
    /// The faces' vertex indices, one face after the other.
    pub face_indices: Vec<u32>,
    /// The number of vertices of each face kept (3 or more).
    pub face_sizes: Vec<u32>,
    /// Faces of fewer than 3 vertices, skipped.
    pub short_faces: u64,
}

/// A source of the body's values.
trait Values {
    /// Starts instance `index` of the element `name`.
    fn begin(&mut self, name: &str, index: u64) -> Result<(), MeshFileError>;
    /// A value as a float (integers converted; `float` values exactly as stored).
    fn float(&mut self, ty: Scalar) -> Result<f64, MeshFileError>;
    /// An integer value (list counts, indices).
    fn int(&mut self, ty: Scalar) -> Result<i64, MeshFileError>;
    /// Checks that `count` list items of type `item` can still be read.
    fn check_list(&self, count: u64, item: Scalar) -> Result<(), MeshFileError>;
    /// Ends the current instance.
    fn end(&mut self) -> Result<(), MeshFileError>;
    /// Where the reader stands, for errors.
    fn position(&self) -> Position;
    fn path(&self) -> &Path;

    fn error(&self, kind: MeshErrorKind) -> MeshFileError {
        MeshFileError::new(self.path(), Some(self.position()), kind)
    }
}

/// Reads the body after `header` in `bytes`.
pub(super) fn read_body(path: &Path, header: &Header, bytes: &[u8]) -> Result<Body, MeshFileError> {
    let body = &bytes[header.body_start..];
    match header.encoding {
        Encoding::Ascii => {
            let Ok(text) = std::str::from_utf8(body) else {
                return Err(MeshFileError::byte(
                    path,
                    header.body_start as u64,
                    MeshErrorKind::Malformed("the ASCII body is not text".into()),
                ));
            };
            let mut v =
                Ascii { path, lines: text.lines().enumerate(), first_line: header.lines + 1, line: 0, tokens: None };
            read_elements(&mut v, header)
        }
        enc => read_elements(
            &mut Binary { path, bytes, at: header.body_start, big_endian: enc == Encoding::BigEndian },
            header,
        ),
    }
}

/// Which vertex property feeds which attribute.
#[derive(Clone, Copy, PartialEq)]
enum Role {
    Skip,
    Position(usize),
    Normal(usize),
    Uv(usize),
}

fn role(name: &str) -> Role {
    match name {
        "x" => Role::Position(0),
        "y" => Role::Position(1),
        "z" => Role::Position(2),
        "nx" => Role::Normal(0),
        "ny" => Role::Normal(1),
        "nz" => Role::Normal(2),
        "u" | "s" | "texture_u" | "texture_s" => Role::Uv(0),
        "v" | "t" | "texture_v" | "texture_t" => Role::Uv(1),
        _ => Role::Skip,
    }
}

fn read_elements(v: &mut impl Values, header: &Header) -> Result<Body, MeshFileError> {
    let path = v.path().to_owned();
    let no_triangles = |why: &str| MeshFileError::file(&path, MeshErrorKind::NoTriangles(why.to_owned()));
    let Some(vertex_el) = header.elements.iter().position(|e| e.name == "vertex") else {
        return Err(no_triangles(": the file has no `vertex` element"));
    };
    // Faces as polygons (`face`), or as triangle strips (`tristrips`, as some scanners wrote them).
    let face_el = header.elements.iter().position(|e| e.name == "face");
    let Some(face_el) = face_el.or_else(|| header.elements.iter().position(|e| e.name == "tristrips")) else {
        let names: Vec<String> = header.elements.iter().map(|e| format!("{} ({})", e.name, e.count)).collect();
        return Err(no_triangles(&format!(
            ": the file has no `face` or `tristrips` element, so no surface to draw; its elements: {}",
            names.join(", ")
        )));
    };
    let strips = header.elements[face_el].name == "tristrips";
    let faces = &header.elements[face_el].name;
    let roles: Vec<Role> = header.elements[vertex_el]
        .properties
        .iter()
        .map(|p| match p {
            Property::Scalar { name, .. } => role(name),
            Property::List { .. } => Role::Skip,
        })
        .collect();
    let has = |want: fn(usize) -> Role, n: usize| (0..n).all(|k| roles.contains(&want(k)));
    if !has(Role::Position, 3) {
        let line = header.elements[vertex_el].line;
        return Err(MeshFileError::line(
            &path,
            line,
            MeshErrorKind::Malformed("the vertex element needs scalar properties x, y and z".into()),
        ));
    }
    let (want_normals, want_uvs) = (has(Role::Normal, 3), has(Role::Uv, 2));
    let index_list = header.elements[face_el]
        .properties
        .iter()
        .position(|p| matches!(p, Property::List { name, .. } if name == "vertex_indices" || name == "vertex_index"));
    let Some(index_list) = index_list else {
        let line = header.elements[face_el].line;
        return Err(MeshFileError::line(
            &path,
            line,
            MeshErrorKind::Malformed(format!(
                "the {faces} element needs a list property vertex_indices (or vertex_index)"
            )),
        ));
    };
    if let Property::List { item, .. } = &header.elements[face_el].properties[index_list] {
        if !item.is_integer() {
            let line = header.elements[face_el].line;
            return Err(MeshFileError::line(
                &path,
                line,
                MeshErrorKind::Malformed("vertex indices must be integers".into()),
            ));
        }
    }

    let mut out = Body::default();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    let mut vertices_read: Option<u64> = None;
    for (e_index, e) in header.elements.iter().enumerate() {
        if e.properties.is_empty() {
            continue;
        }
        if e_index == vertex_el {
            // The count fits the file (checked with the header), so these allocations are bounded.
            out.positions.reserve_exact(e.count as usize);
            if want_normals {
                normals.reserve_exact(e.count as usize);
            }
            if want_uvs {
                uvs.reserve_exact(e.count as usize);
            }
        }
        for i in 0..e.count {
            v.begin(&e.name, i)?;
            let start = v.position();
            let (mut p, mut n, mut uv) = ([0f32; 3], [0f32; 3], [0f32; 2]);
            for (k, prop) in e.properties.iter().enumerate() {
                match prop {
                    Property::Scalar { ty, .. } => {
                        let value = v.float(*ty)? as f32;
                        if e_index != vertex_el {
                            continue;
                        }
                        match roles[k] {
                            Role::Position(a) => p[a] = value,
                            Role::Normal(a) => n[a] = value,
                            Role::Uv(a) => uv[a] = value,
                            Role::Skip => {}
                        }
                    }
                    Property::List { count, item, .. } => {
                        let c = v.int(*count)?;
                        if c < 0 {
                            return Err(v.error(MeshErrorKind::Malformed(format!("negative list count {c}"))));
                        }
                        let c = c as u64;
                        v.check_list(c, *item)?;
                        if e_index == face_el && k == index_list && strips {
                            read_strip(v, c, *item, vertices_read, &mut out)?;
                        } else if e_index == face_el && k == index_list && c >= 3 {
                            read_face(v, c, *item, vertices_read, &mut out)?;
                        } else {
                            if e_index == face_el && k == index_list {
                                out.short_faces += 1;
                            }
                            for _ in 0..c {
                                v.float(*item)?;
                            }
                        }
                    }
                }
            }
            v.end()?;
            if e_index == vertex_el {
                if let Some(bad) = p.iter().find(|c| !c.is_finite()) {
                    return Err(MeshFileError::new(
                        &path,
                        Some(start),
                        MeshErrorKind::NonFinite { what: format!("vertex {i}'s position"), value: bad.to_string() },
                    ));
                }
                out.positions.push(Vec3::from(p));
                if want_normals {
                    normals.push(Vec3::from(n));
                }
                if want_uvs {
                    uvs.push(Vec2::from(uv));
                }
            }
        }
        if e_index == vertex_el {
            vertices_read = Some(e.count);
        }
    }
    // Faces read before the vertices could not be checked as they were read.
    let vertices = out.positions.len();
    if let Some(bad) = out.face_indices.iter().find(|&&i| i as usize >= vertices) {
        return Err(MeshFileError::file(
            &path,
            MeshErrorKind::IndexOutOfRange {
                what: "vertex",
                index: bad.to_string(),
                available: vertices as u64,
                context: "",
            },
        ));
    }
    out.normals = want_normals.then_some(normals);
    out.uvs = want_uvs.then_some(uvs);
    Ok(out)
}

fn read_face(
    v: &mut impl Values,
    count: u64,
    item: Scalar,
    vertices: Option<u64>,
    out: &mut Body,
) -> Result<(), MeshFileError> {
    let limit = vertices.unwrap_or(u32::MAX as u64);
    for _ in 0..count {
        let index = v.int(item)?;
        if index < 0 || index as u64 >= limit {
            return Err(v.error(MeshErrorKind::IndexOutOfRange {
                what: "vertex",
                index: index.to_string(),
                available: limit,
                context: if vertices.is_some() { "" } else { " (indices must fit 32 bits)" },
            }));
        }
        out.face_indices.push(index as u32);
    }
    out.face_sizes.push(count as u32);
    Ok(())
}

/// One triangle strip: `-1` ends a strip and starts the next; in each, vertices `j, j+1, j+2` make
/// a triangle, every second one with its first two swapped so that all keep the strip's winding.
/// Triangles with a repeated vertex (the joins that strippers insert) are dropped.
fn read_strip(
    v: &mut impl Values,
    count: u64,
    item: Scalar,
    vertices: Option<u64>,
    out: &mut Body,
) -> Result<(), MeshFileError> {
    let limit = vertices.unwrap_or(u32::MAX as u64);
    let mut strip: Vec<u32> = Vec::new();
    let emit = |strip: &mut Vec<u32>, out: &mut Body| {
        for j in 0..strip.len().saturating_sub(2) {
            let (a, b, c) = (strip[j], strip[j + 1], strip[j + 2]);
            let t = if j % 2 == 0 { [a, b, c] } else { [b, a, c] };
            if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                out.face_indices.extend(t);
                out.face_sizes.push(3);
            }
        }
        strip.clear();
    };
    for _ in 0..count {
        let index = v.int(item)?;
        if index == -1 {
            emit(&mut strip, out);
            continue;
        }
        if index < 0 || index as u64 >= limit {
            return Err(v.error(MeshErrorKind::IndexOutOfRange {
                what: "vertex",
                index: index.to_string(),
                available: limit,
                context: if vertices.is_some() { " (-1 ends a strip)" } else { " (indices must fit 32 bits)" },
            }));
        }
        strip.push(index as u32);
    }
    emit(&mut strip, out);
    Ok(())
}

/// ASCII bodies: one element instance per line.
struct Ascii<'a> {
    path: &'a Path,
    lines: std::iter::Enumerate<std::str::Lines<'a>>,
    first_line: usize,
    line: usize,
    tokens: Option<std::str::SplitWhitespace<'a>>,
}

impl<'a> Ascii<'a> {
    fn token(&mut self, expected: &'static str) -> Result<&'a str, MeshFileError> {
        let next = self.tokens.as_mut().and_then(|t| t.next());
        next.ok_or_else(|| {
            MeshFileError::line(
                self.path,
                self.line,
                MeshErrorKind::Truncated(format!("the line ends where {expected} was expected")),
            )
        })
    }
}

impl Values for Ascii<'_> {
    fn begin(&mut self, name: &str, index: u64) -> Result<(), MeshFileError> {
        for (i, text) in self.lines.by_ref() {
            if !text.trim().is_empty() {
                self.line = self.first_line + i;
                self.tokens = Some(text.split_whitespace());
                return Ok(());
            }
        }
        Err(MeshFileError::line(
            self.path,
            self.line.max(self.first_line),
            MeshErrorKind::Truncated(format!("{name} {index} is missing")),
        ))
    }

    fn float(&mut self, ty: Scalar) -> Result<f64, MeshFileError> {
        let token = self.token("a number")?;
        let parsed = match ty {
            // `float` values parse straight to the nearest f32, as a binary file would store them.
            Scalar::F32 => token.parse::<f32>().map(f64::from).ok(),
            Scalar::F64 => token.parse::<f64>().ok(),
            _ => token.parse::<i64>().ok().map(|i| i as f64),
        };
        let bad = |line| {
            MeshFileError::line(
                self.path,
                line,
                MeshErrorKind::BadNumber { token: token.to_owned(), expected: "a number" },
            )
        };
        parsed.ok_or_else(|| bad(self.line))
    }

    fn int(&mut self, ty: Scalar) -> Result<i64, MeshFileError> {
        let token = self.token("an integer")?;
        let expected = if ty.is_integer() { "an integer" } else { "an integer (indices and counts are integers)" };
        token.parse::<i64>().map_err(|_| {
            MeshFileError::line(self.path, self.line, MeshErrorKind::BadNumber { token: token.to_owned(), expected })
        })
    }

    fn check_list(&self, count: u64, _item: Scalar) -> Result<(), MeshFileError> {
        let left = self.tokens.clone().map_or(0, |t| t.count()) as u64;
        if count > left {
            return Err(self.error(MeshErrorKind::CountTooLarge {
                what: "list".into(),
                count,
                needed: count,
                available: left,
            }));
        }
        Ok(())
    }

    fn end(&mut self) -> Result<(), MeshFileError> {
        let extra = self.tokens.as_mut().map_or(0, |t| t.count());
        if extra > 0 {
            return Err(self.error(MeshErrorKind::Malformed(format!("{extra} more value(s) than the header declares"))));
        }
        Ok(())
    }

    fn position(&self) -> Position {
        Position::Line(self.line)
    }

    fn path(&self) -> &Path {
        self.path
    }
}

/// Binary bodies, little- or big-endian.
struct Binary<'a> {
    path: &'a Path,
    bytes: &'a [u8],
    at: usize,
    big_endian: bool,
}

impl Binary<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], MeshFileError> {
        let Some(chunk) = self.bytes.get(self.at..self.at + N) else {
            return Err(self.error(MeshErrorKind::Truncated(format!(
                "{N} byte(s) needed, {} left",
                self.bytes.len() - self.at.min(self.bytes.len())
            ))));
        };
        let mut out = [0u8; N];
        out.copy_from_slice(chunk);
        if !self.big_endian {
            out.reverse();
        }
        self.at += N;
        // Big-endian order from here on.
        Ok(out)
    }
}

impl Values for Binary<'_> {
    fn begin(&mut self, _name: &str, _index: u64) -> Result<(), MeshFileError> {
        Ok(())
    }

    fn float(&mut self, ty: Scalar) -> Result<f64, MeshFileError> {
        Ok(match ty {
            Scalar::F32 => f32::from_be_bytes(self.take()?) as f64,
            Scalar::F64 => f64::from_be_bytes(self.take()?),
            _ => self.int(ty)? as f64,
        })
    }

    fn int(&mut self, ty: Scalar) -> Result<i64, MeshFileError> {
        Ok(match ty {
            Scalar::I8 => i8::from_be_bytes(self.take()?) as i64,
            Scalar::U8 => u8::from_be_bytes(self.take()?) as i64,
            Scalar::I16 => i16::from_be_bytes(self.take()?) as i64,
            Scalar::U16 => u16::from_be_bytes(self.take()?) as i64,
            Scalar::I32 => i32::from_be_bytes(self.take()?) as i64,
            Scalar::U32 => u32::from_be_bytes(self.take()?) as i64,
            Scalar::F32 | Scalar::F64 => {
                let at = self.at;
                let f = self.float(ty)?;
                if f.fract() != 0.0 || f.abs() >= 9.0e15 {
                    return Err(MeshFileError::byte(
                        self.path,
                        at as u64,
                        MeshErrorKind::BadNumber { token: f.to_string(), expected: "an integer" },
                    ));
                }
                f as i64
            }
        })
    }

    fn check_list(&self, count: u64, item: Scalar) -> Result<(), MeshFileError> {
        let available = (self.bytes.len() - self.at) as u64;
        let needed = count.saturating_mul(item.size());
        if needed > available {
            return Err(self.error(MeshErrorKind::CountTooLarge { what: "list".into(), count, needed, available }));
        }
        Ok(())
    }

    fn end(&mut self) -> Result<(), MeshFileError> {
        Ok(())
    }

    fn position(&self) -> Position {
        Position::Byte(self.at as u64)
    }

    fn path(&self) -> &Path {
        self.path
    }
}
