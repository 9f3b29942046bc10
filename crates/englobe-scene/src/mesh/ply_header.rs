//! The header of a Stanford PLY file (Turk 1994, "The PLY Polygon File Format"): the `format`
//! line, the `element` and `property` declarations, and where the body starts. Parsed from the
//! bytes, with `\n` or `\r\n` line ends, and checked against the file's length before the body is
//! read, so that `element vertex 4294967295` in a 100-byte file is an error, not an attempt at a
//! 50 GB allocation.

use std::path::Path;

use super::error::{MeshErrorKind, MeshFileError};

/// Longest header read, in bytes.
const MAX_HEADER_BYTES: usize = 1 << 20;

/// How the body is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Encoding {
    Ascii,
    LittleEndian,
    BigEndian,
}

/// The scalar types of PLY.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    /// Bytes in a binary body.
    pub(super) fn size(self) -> u64 {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    pub(super) fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

/// One property of an element.
#[derive(Clone, Debug)]
pub(super) enum Property {
    Scalar { name: String, ty: Scalar },
    List { name: String, count: Scalar, item: Scalar },
}

impl Property {
    /// The fewest bytes the property takes in a binary body (an empty list for lists).
    fn min_binary_size(&self) -> u64 {
        match self {
            Property::Scalar { ty, .. } => ty.size(),
            Property::List { count, .. } => count.size(),
        }
    }
}

/// One element declaration.
#[derive(Clone, Debug)]
pub(super) struct Element {
    pub name: String,
    pub count: u64,
    pub properties: Vec<Property>,
    /// Header line of the declaration.
    pub line: usize,
}

/// A parsed header.
#[derive(Debug)]
pub(super) struct Header {
    pub encoding: Encoding,
    pub elements: Vec<Element>,
    /// Byte offset of the body.
    pub body_start: usize,
    /// Number of header lines (the body's first line is the next one).
    pub lines: usize,
}

/// Reads the header: `ply`, `format`, then `element` and `property` lines up to `end_header`.
pub(super) fn parse_header(path: &Path, bytes: &[u8]) -> Result<Header, MeshFileError> {
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut start = 0usize;
    let mut line_no = 0usize;
    loop {
        let Some(len) = bytes[start..].iter().position(|&b| b == b'\n') else {
            return Err(MeshFileError::byte(
                path,
                bytes.len() as u64,
                MeshErrorKind::Truncated("the header has no `end_header` line".into()),
            ));
        };
        line_no += 1;
        let err = |kind| MeshFileError::line(path, line_no, kind);
        let raw = &bytes[start..start + len];
        start += len + 1;
        if start > MAX_HEADER_BYTES {
            return Err(err(MeshErrorKind::Malformed(format!("the header is longer than {MAX_HEADER_BYTES} bytes"))));
        }
        let Ok(text) = std::str::from_utf8(raw) else {
            return Err(err(MeshErrorKind::Malformed("the header is not ASCII text".into())));
        };
        let text = text.trim_end_matches('\r');
        if line_no == 1 {
            if text.trim() != "ply" {
                return Err(err(MeshErrorKind::Malformed("not a PLY file: the first line must be `ply`".into())));
            }
            continue;
        }
        let words: Vec<&str> = text.split_whitespace().collect();
        match words.as_slice() {
            [] => {}
            ["comment", ..] | ["obj_info", ..] => {}
            ["format", enc, version] => {
                encoding = Some(match *enc {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::LittleEndian,
                    "binary_big_endian" => Encoding::BigEndian,
                    other => {
                        return Err(err(MeshErrorKind::Unsupported(format!(
                            "PLY format `{other}`: expected ascii, binary_little_endian or binary_big_endian"
                        ))));
                    }
                });
                if *version != "1.0" {
                    return Err(err(MeshErrorKind::Unsupported(format!("PLY version {version}: expected 1.0"))));
                }
            }
            ["element", name, count] => {
                let count = count.parse::<u64>().map_err(|_| {
                    err(MeshErrorKind::BadNumber {
                        token: (*count).to_owned(),
                        expected: "an element count (0 or more)",
                    })
                })?;
                elements.push(Element { name: (*name).to_owned(), count, properties: Vec::new(), line: line_no });
            }
            ["property", rest @ ..] => {
                let Some(element) = elements.last_mut() else {
                    return Err(err(MeshErrorKind::Malformed("a property before any element".into())));
                };
                let scalar = |name: &str| {
                    Scalar::parse(name).ok_or_else(|| {
                        err(MeshErrorKind::Malformed(format!(
                            "unknown property type `{name}`: expected char, uchar, short, ushort, int, uint, float or double"
                        )))
                    })
                };
                let property = match rest {
                    ["list", count, item, name] => {
                        let count = scalar(count)?;
                        if !count.is_integer() {
                            return Err(err(MeshErrorKind::Malformed("a list count must have an integer type".into())));
                        }
                        Property::List { name: (*name).to_owned(), count, item: scalar(item)? }
                    }
                    [ty, name] => Property::Scalar { name: (*name).to_owned(), ty: scalar(ty)? },
                    _ => {
                        return Err(err(MeshErrorKind::Malformed(
                            "expected `property TYPE NAME` or `property list COUNT_TYPE ITEM_TYPE NAME`".into(),
                        )));
                    }
                };
                element.properties.push(property);
            }
            ["end_header"] => break,
            _ => {
                return Err(err(MeshErrorKind::Malformed(format!(
                    "unexpected header line `{text}`: expected format, element, property, comment or end_header"
                ))));
            }
        }
    }
    let Some(encoding) = encoding else {
        return Err(MeshFileError::line(path, 2, MeshErrorKind::Malformed("the header has no `format` line".into())));
    };
    Ok(Header { encoding, elements, body_start: start, lines: line_no })
}

/// Refuses counts the file cannot hold: every element needs at least a few bytes per instance
/// (its fixed-size properties in binary, one character and a separator per value in ASCII).
pub(super) fn check_sizes(path: &Path, header: &Header, file_len: u64) -> Result<(), MeshFileError> {
    let available = file_len - header.body_start as u64;
    let mut needed_so_far: u64 = 0;
    for e in &header.elements {
        let per_item = match header.encoding {
            Encoding::Ascii => 2 * e.properties.len() as u64,
            _ => e.properties.iter().map(Property::min_binary_size).sum(),
        };
        let needed = e.count.saturating_mul(per_item).saturating_add(needed_so_far);
        // An element with no property takes no byte: it still may not declare more than 2^32
        // instances, which englobe could not index. (The last ASCII value may lack its
        // separator, hence the one byte of slack.)
        if needed > available.saturating_add(1) || e.count > u32::MAX as u64 {
            return Err(MeshFileError::line(
                path,
                e.line,
                MeshErrorKind::CountTooLarge {
                    what: format!("element `{}`", e.name),
                    count: e.count,
                    needed,
                    available,
                },
            ));
        }
        needed_so_far = needed;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_with_crlf_and_comments() {
        let text = b"ply\r\nformat binary_big_endian 1.0\r\ncomment hi\r\nelement vertex 2\r\nproperty float x\r\n\
                     property list uchar int vertex_indices\r\nend_header\r\nBODY";
        let h = parse_header(Path::new("t.ply"), text).unwrap();
        assert_eq!(h.encoding, Encoding::BigEndian);
        assert_eq!(h.lines, 7);
        assert_eq!(&text[h.body_start..], b"BODY");
        assert_eq!(h.elements[0].properties.len(), 2);
    }

    #[test]
    fn bad_headers_name_their_line() {
        for (text, line) in [
            (&b"plx\nformat ascii 1.0\nend_header\n"[..], 1),
            (b"ply\nformat ascii 2.0\nend_header\n", 2),
            (b"ply\nformat ascii 1.0\nproperty float x\nend_header\n", 3),
            (b"ply\nformat ascii 1.0\nelement vertex -3\nend_header\n", 3),
            (b"ply\nformat ascii 1.0\nelement vertex 3\nproperty list float int v\nend_header\n", 4),
            (b"ply\nformat ascii 1.0\nelement vertex 3\nproperty quad x\nend_header\n", 4),
        ] {
            let e = parse_header(Path::new("t.ply"), text).unwrap_err();
            assert_eq!(e.line_number(), Some(line), "{e}");
        }
        let e = parse_header(Path::new("t.ply"), b"ply\nformat ascii 1.0\nelement vertex 3\n").unwrap_err();
        assert!(matches!(e.kind, MeshErrorKind::Truncated(_)), "{e}");
    }
}
