//! The binary data of a glTF 2.0 file: buffers (the GLB's binary chunk, files beside the `.gltf`,
//! or base64 data URIs) and the accessors that read typed elements out of them.
//!
//! The `gltf` crate's own readers trust the JSON's offsets, strides and counts; some of its paths
//! panic or read garbage when they lie. Here every accessor is checked against its buffer view,
//! and every view against its buffer, in 128-bit arithmetic, before a single element is read:
//! a zero count, a count of 2^62, a stride smaller than the element or an accessor that runs past
//! its view are refused with the JSON path of the offender.

use std::borrow::Cow;
use std::path::Path;

use gltf::json;
use gltf::json::accessor::{ComponentType, Type};

use super::error::{MeshErrorKind, MeshFileError, Position};
use super::loaded::MAX_MESH_FILE_BYTES;
use super::read::read_limited;

/// The buffers of a document, loaded when first used.
pub(super) struct Buffers<'a> {
    path: &'a Path,
    glb_bin: Option<&'a [u8]>,
    loaded: Vec<Option<Cow<'a, [u8]>>>,
}

/// A checked accessor: where its elements are and how to read them.
pub(super) struct Accessor<'a> {
    index: usize,
    data: &'a [u8],
    /// Byte of element 0 in `data`.
    start: usize,
    stride: usize,
    /// Number of elements.
    pub count: usize,
    component: ComponentType,
    dims: usize,
    normalized: bool,
}

fn json_err(path: &Path, at: String, kind: MeshErrorKind) -> MeshFileError {
    MeshFileError::new(path, Some(Position::Json(at)), kind)
}

impl<'a> Buffers<'a> {
    pub(super) fn new(path: &'a Path, root: &json::Root, glb_bin: Option<&'a [u8]>) -> Self {
        Buffers { path, glb_bin, loaded: vec![None; root.buffers.len()] }
    }

    /// The bytes of buffer `index`, at least its declared `byteLength` long.
    fn buffer(&mut self, root: &json::Root, index: usize) -> Result<&[u8], MeshFileError> {
        let at = || format!("buffers[{index}]");
        let Some(def) = root.buffers.get(index) else {
            return Err(json_err(self.path, at(), MeshErrorKind::Malformed("no such buffer".into())));
        };
        if self.loaded[index].is_none() {
            let data: Cow<'a, [u8]> = match def.uri.as_deref() {
                None => match self.glb_bin {
                    Some(bin) if index == 0 => Cow::Borrowed(bin),
                    _ => {
                        return Err(json_err(
                            self.path,
                            at(),
                            MeshErrorKind::Malformed("a buffer without uri, but no GLB binary chunk to hold it".into()),
                        ));
                    }
                },
                Some(uri) if uri.starts_with("data:") => {
                    let Some((_, encoded)) = uri.split_once(";base64,") else {
                        return Err(json_err(
                            self.path,
                            at(),
                            MeshErrorKind::Unsupported("a data URI that is not base64".into()),
                        ));
                    };
                    Cow::Owned(
                        decode_base64(encoded).map_err(|e| json_err(self.path, at(), MeshErrorKind::Malformed(e)))?,
                    )
                }
                Some(uri) if uri.contains("://") => {
                    return Err(json_err(
                        self.path,
                        at(),
                        MeshErrorKind::Unsupported(format!("the external URI `{uri}`")),
                    ));
                }
                Some(uri) => {
                    let file = self.path.parent().unwrap_or(Path::new("")).join(percent_decode(uri));
                    // The error names the glTF file and the buffer, then the file it points to.
                    let referenced = |e| {
                        json_err(self.path, format!("buffers[{index}].uri"), MeshErrorKind::Referenced(Box::new(e)))
                    };
                    Cow::Owned(read_limited(&file, MAX_MESH_FILE_BYTES).map_err(referenced)?)
                }
            };
            if (data.len() as u64) < def.byte_length.0 {
                return Err(json_err(
                    self.path,
                    format!("buffers[{index}].byteLength"),
                    MeshErrorKind::Truncated(format!(
                        "the buffer declares {} bytes but holds {}",
                        def.byte_length.0,
                        data.len()
                    )),
                ));
            }
            self.loaded[index] = Some(data);
        }
        Ok(self.loaded[index].as_deref().unwrap_or(&[]))
    }

    /// The bytes of buffer view `index` (an image's), checked against its buffer.
    pub(super) fn view(&mut self, root: &json::Root, index: usize) -> Result<&[u8], MeshFileError> {
        let path = self.path;
        let Some(view) = root.buffer_views.get(index) else {
            return Err(json_err(
                path,
                format!("bufferViews[{index}]"),
                MeshErrorKind::Malformed("no such buffer view".into()),
            ));
        };
        let start = view.byte_offset.map_or(0, |o| o.0) as u128;
        let end = start + view.byte_length.0 as u128;
        let buffer_index = view.buffer.value();
        let declared = root.buffers.get(buffer_index).map_or(0, |b| b.byte_length.0) as u128;
        if end > declared {
            return Err(json_err(
                path,
                format!("bufferViews[{index}]"),
                MeshErrorKind::Malformed(format!(
                    "the view covers bytes {start}..{end} of buffers[{buffer_index}], which has {declared}"
                )),
            ));
        }
        let data = self.buffer(root, buffer_index)?;
        // `buffer` holds at least the declared length, which `end` does not pass.
        Ok(&data[start as usize..end as usize])
    }

    /// Accessor `index`, checked, if its type is one of `types` and its component one of
    /// `components` (`what` names its use in errors).
    pub(super) fn accessor(
        &mut self,
        root: &json::Root,
        index: usize,
        what: &str,
        types: &[Type],
        components: &[ComponentType],
    ) -> Result<Accessor<'_>, MeshFileError> {
        let path = self.path;
        let at = |field: &str| format!("accessors[{index}]{field}");
        let bad = |field: &str, kind| json_err(path, at(field), kind);
        let Some(acc) = root.accessors.get(index) else {
            return Err(bad("", MeshErrorKind::Malformed(format!("{what} refers to a missing accessor"))));
        };
        if acc.sparse.is_some() {
            return Err(bad(".sparse", MeshErrorKind::Unsupported("sparse accessors".into())));
        }
        let (json::validation::Checked::Valid(ty), json::validation::Checked::Valid(component)) =
            (acc.type_, acc.component_type)
        else {
            return Err(bad("", MeshErrorKind::Malformed("an invalid type or componentType".into())));
        };
        let component = component.0;
        if !types.contains(&ty) || !components.contains(&component) {
            return Err(bad(
                "",
                MeshErrorKind::Malformed(format!(
                    "{what} must be {types:?} of {components:?}, found {ty:?} of {component:?}"
                )),
            ));
        }
        let count = acc.count.0;
        if count == 0 {
            return Err(bad(".count", MeshErrorKind::Malformed("the count is 0; glTF requires at least 1".into())));
        }
        let Some(view_index) = acc.buffer_view else {
            return Err(bad("", MeshErrorKind::Unsupported("an accessor without a bufferView".into())));
        };
        let view_index = view_index.value();
        let Some(view) = root.buffer_views.get(view_index) else {
            return Err(bad(".bufferView", MeshErrorKind::Malformed("no such buffer view".into())));
        };
        let dims = ty.multiplicity();
        let element = component.size() * dims;
        let stride = view.byte_stride.map_or(element, |s| s.0);
        if stride < element {
            return Err(json_err(
                path,
                format!("bufferViews[{view_index}].byteStride"),
                MeshErrorKind::Malformed(format!(
                    "the stride {stride} is smaller than the {element}-byte elements of accessors[{index}]"
                )),
            ));
        }
        let acc_offset = acc.byte_offset.map_or(0, |o| o.0) as u128;
        let view_offset = view.byte_offset.map_or(0, |o| o.0) as u128;
        let view_length = view.byte_length.0 as u128;
        let extent = acc_offset + (count as u128 - 1) * stride as u128 + element as u128;
        if extent > view_length {
            return Err(bad(
                ".count",
                MeshErrorKind::CountTooLarge {
                    what: format!(
                        "{what} (accessor of {element}-byte elements every {stride} bytes from byte {acc_offset})"
                    ),
                    count,
                    needed: extent.min(u64::MAX as u128) as u64,
                    available: view.byte_length.0,
                },
            ));
        }
        let buffer_index = view.buffer.value();
        let Some(buffer) = root.buffers.get(buffer_index) else {
            return Err(json_err(
                path,
                format!("bufferViews[{view_index}].buffer"),
                MeshErrorKind::Malformed("refers to a missing buffer".into()),
            ));
        };
        let buffer_length = buffer.byte_length.0 as u128;
        if view_offset + view_length > buffer_length {
            return Err(json_err(
                path,
                format!("bufferViews[{view_index}]"),
                MeshErrorKind::Malformed(format!(
                    "the view covers bytes {view_offset}..{} of buffers[{buffer_index}], which has {buffer_length}",
                    view_offset + view_length
                )),
            ));
        }
        let data = self.buffer(root, buffer_index)?;
        // All of the above fit in the buffer, whose length fits `usize`.
        Ok(Accessor {
            index,
            data,
            start: (view_offset + acc_offset) as usize,
            stride,
            count: count as usize,
            component,
            dims,
            normalized: acc.normalized,
        })
    }
}

impl Accessor<'_> {
    /// Whether integer components are read as normalised (`normalized: true`); always true of
    /// floats, which have nothing to normalise.
    pub(super) fn is_normalized(&self) -> bool {
        self.component == ComponentType::F32 || self.normalized
    }

    /// Component `c` of element `k` as a float (normalised integers mapped to 0..=1).
    #[inline]
    pub(super) fn float(&self, k: usize, c: usize) -> f32 {
        let at = self.start + k * self.stride + c * self.component.size();
        let b = &self.data[at..at + self.component.size()];
        let (value, scale) = match self.component {
            ComponentType::F32 => return f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            ComponentType::U8 => (b[0] as f32, 255.0),
            ComponentType::I8 => (b[0] as i8 as f32, 127.0),
            ComponentType::U16 => (u16::from_le_bytes([b[0], b[1]]) as f32, 65535.0),
            ComponentType::I16 => (i16::from_le_bytes([b[0], b[1]]) as f32, 32767.0),
            ComponentType::U32 => (u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32, 4294967295.0),
        };
        if self.normalized { (value / scale).max(-1.0) } else { value }
    }

    /// Element `k` of an unsigned integer scalar accessor.
    #[inline]
    pub(super) fn index(&self, k: usize) -> u32 {
        let at = self.start + k * self.stride;
        let b = &self.data[at..];
        match self.component {
            ComponentType::U8 => b[0] as u32,
            ComponentType::U16 => u16::from_le_bytes([b[0], b[1]]) as u32,
            _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        }
    }

    /// All elements as vectors of `N` floats, refusing NaN and infinities.
    pub(super) fn vectors<const N: usize>(&self, path: &Path, what: &str) -> Result<Vec<[f32; N]>, MeshFileError> {
        debug_assert_eq!(N, self.dims);
        let mut out = Vec::with_capacity(self.count);
        for k in 0..self.count {
            let v: [f32; N] = std::array::from_fn(|c| self.float(k, c));
            if v.iter().any(|x| !x.is_finite()) {
                return Err(self.element_error(
                    path,
                    k,
                    MeshErrorKind::NonFinite { what: what.into(), value: format!("{v:?}") },
                ));
            }
            out.push(v);
        }
        Ok(out)
    }

    /// An error about element `k`, naming the accessor, the element and its byte in the buffer.
    pub(super) fn element_error(&self, path: &Path, k: usize, kind: MeshErrorKind) -> MeshFileError {
        let byte = self.start + k * self.stride;
        json_err(path, format!("accessors[{}] element {k} (byte {byte} of its buffer)", self.index), kind)
    }
}

/// Decodes standard base64 (with or without padding).
pub(super) fn decode_base64(text: &str) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3);
    let (mut acc, mut bits) = (0u32, 0u32);
    for (i, c) in text.bytes().enumerate() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            b'=' => break,
            _ => return Err(format!("invalid base64 character at position {i} of the data URI")),
        };
        acc = (acc << 6) | v as u32;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
        }
    }
    Ok(out)
}

/// `%20` and friends in relative URIs.
pub(super) fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            if let (Some(h), Some(l)) = (hex(bytes[i + 1]), hex(bytes[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_and_percent_decoding() {
        assert_eq!(decode_base64("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(decode_base64("AAECAw").unwrap(), [0, 1, 2, 3]);
        assert!(decode_base64("a b").is_err());
        assert_eq!(percent_decode("my%20file.bin"), "my file.bin");
        assert_eq!(percent_decode("100%"), "100%");
        assert_eq!(percent_decode("a%2"), "a%2");
    }
}
