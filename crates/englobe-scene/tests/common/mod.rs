//! Helpers of the glTF tests: files written into a test's folder, PNG images and base64 data
//! URIs made from texels.

use std::path::{Path, PathBuf};

/// Standard base64 with padding, as glTF's data URIs hold buffers and images.
pub fn base64(bytes: &[u8]) -> String {
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            out.push(if k <= c.len() { A[(n >> (18 - 6 * k) & 63) as usize] as char } else { '=' });
        }
    }
    out
}

/// A PNG file's bytes, `w` x `h` RGBA texels row by row.
pub fn png(w: u32, h: u32, texels: &[[u8; 4]]) -> Vec<u8> {
    let img = image::RgbaImage::from_raw(w, h, texels.iter().flatten().copied().collect()).unwrap();
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// Writes `bytes` as `dir/name` and returns its path.
pub fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}
