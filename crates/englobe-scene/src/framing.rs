//! A scene that frames one mesh file, so that a person sees a file without writing a scene:
//! `englobe render bunny.obj`, and `englobe scene bunny.obj` to print it as a starting point.
//!
//! The scene is written as scene text, not built as a [`crate::Scene`], so that what is rendered
//! and what is printed are one thing: the printed file parses to the same scene and draws the same
//! image. The camera stands on the mesh's bounding sphere (the sphere around its bounding box) at
//! the distance where the sphere fills the field of view, a little above and to the side; a
//! ground plane touches the mesh's lowest point; a key light above and beside the camera falls off
//! to about unit irradiance at the mesh, a dim directional fill and an ambient term open the
//! shadows, and the background stands for a sky.

use std::fmt::Write;
use std::path::Path;

use englobe::Vec3;

use crate::mesh::{LoadedMesh, MeshFileError, load_mesh_file};

/// Vertical field of view of the framing camera, in degrees.
pub const FRAMING_FOV: f32 = 35.0;

/// The scene text that frames the mesh file `path` (named in the text as given, so the scene
/// resolves it from the folder `path` is relative to).
pub fn framing_scene(path: &Path) -> Result<String, MeshFileError> {
    let mesh = load_mesh_file(path)?;
    Ok(framing_scene_for(path, &mesh))
}

/// [`framing_scene`] for a mesh already loaded.
pub fn framing_scene_for(path: &Path, mesh: &LoadedMesh) -> String {
    let bounds = mesh.mesh.bounds();
    let centre = bounds.center();
    let radius = (bounds.extent().length() * 0.5).max(1e-6);
    let distance = radius / (FRAMING_FOV.to_radians() * 0.5).sin() * 1.05;
    // Right-handed, looking along +z: the camera in front (-z), a little to the side and above.
    let view = Vec3::new(0.35, 0.22, -1.0).normalize();
    let eye = centre + view * distance;
    let light = centre + Vec3::new(-1.5, 2.5, -2.0) * radius * 2.0;
    let light_intensity = (light - centre).length_squared() * 1.1;
    let name = toml::Value::String(path.display().to_string());
    let v = |p: Vec3| format!("[{}, {}, {}]", p.x, p.y, p.z);
    let mut s = String::new();
    let _ = writeln!(s, "# {}, framed by `englobe scene`: edit freely.", path.display());
    let _ = writeln!(
        s,
        "# {} triangles; bounds {} to {}; bounding sphere radius {radius}.\n",
        mesh.mesh.len(),
        v(bounds.min),
        v(bounds.max)
    );
    let _ = writeln!(s, "[image]\nwidth = 640\nheight = 480\nsamples = 4\nmax_depth = 4");
    let _ = writeln!(s, "background = [0.62, 0.72, 0.85]\nambient = [0.1, 0.1, 0.12]\n");
    let _ = writeln!(s, "[camera]\nposition = {}\nlook_at = {}\nfov = {FRAMING_FOV}\n", v(eye), v(centre));
    let _ =
        writeln!(s, "[materials.clay]\ndiffuse = [0.8, 0.62, 0.5]\nspecular = [0.15, 0.15, 0.15]\nshininess = 30\n");
    let _ = writeln!(s, "[materials.ground]\ndiffuse = [0.72, 0.72, 0.7]\n");
    let _ = writeln!(s, "[[point_light]]\nposition = {}\nintensity = {light_intensity}\n", v(light));
    let _ = writeln!(s, "[[directional_light]]\ndirection = [0.4, -1.0, 0.6]\nintensity = 0.3\n");
    let _ = writeln!(s, "[[plane]]\npoint = {}\nnormal = [0.0, 1.0, 0.0]\nmaterial = \"ground\"\n", v(bounds.min));
    let _ = writeln!(s, "[[mesh]]\npath = {name}\nmaterial = \"clay\"");
    s
}

/// The camera position of frame `k` of `frames` turning around the vertical axis through
/// `look_at`, starting from `position`.
pub fn turntable_position(position: Vec3, look_at: Vec3, k: u32, frames: u32) -> Vec3 {
    let angle = std::f32::consts::TAU * k as f32 / frames.max(1) as f32;
    let offset = position - look_at;
    let (sin, cos) = angle.sin_cos();
    look_at + Vec3::new(offset.x * cos + offset.z * sin, offset.y, -offset.x * sin + offset.z * cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_turntable_keeps_the_distance_and_height_and_comes_back() {
        let (p, c) = (Vec3::new(1.0, 2.0, -3.0), Vec3::new(0.5, 0.0, 0.0));
        for k in 0..8 {
            let q = turntable_position(p, c, k, 8);
            assert!(((q - c).length() - (p - c).length()).abs() < 1e-5);
            assert_eq!(q.y, p.y);
        }
        assert!((turntable_position(p, c, 8, 8) - p).length() < 1e-5);
        assert!((turntable_position(p, c, 4, 8) - (2.0 * c - p).with_y(p.y)).length() < 1e-5);
    }
}
