//! `englobe info FILE`: what a mesh file or a scene file holds (triangles, vertices, bounds,
//! materials with their model, factors and texture slots, textures with their sizes and which
//! could not be read, instances, warnings), or the error that refuses it; for an OpenEXR image,
//! its mean colour, and how it differs from a reference image (see [`crate::image_stats`]).

use std::collections::HashSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::Args;
use englobe::{Aabb, Bounded, Object, Shape, TriangleMesh};
use englobe_scene::mesh::{DEFAULT_SMOOTH_ANGLE, LoadedMesh, MeshOptions, load_mesh_file_with};
use englobe_scene::{Material, MaterialModel, Scene, Texture, load_scene};

#[derive(Args)]
pub struct InfoArgs {
    /// A mesh file (.obj, .ply, .gltf, .glb), a scene file (.toml, or pbrt-v4 .pbrt), or an
    /// OpenEXR image (.exr: its size and mean linear RGB).
    file: PathBuf,
    /// For an OpenEXR image: also the mean RGB of the pixels X0..X1, Y0..Y1 (row 0 at the top).
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = crate::image_stats::parse_patch)]
    patch: Option<crate::image_stats::Patch>,
    /// For an OpenEXR image: how it differs from this reference image of the same size (ratio of
    /// the means, of the patch's means, RMSE and relative MSE), as when comparing renderers.
    #[arg(long, value_name = "REFERENCE.exr")]
    against: Option<PathBuf>,
    /// For a pbrt scene: refuse it, at the first thing englobe would skip or approximate, instead
    /// of listing those as warnings.
    #[arg(long)]
    strict: bool,
}

pub fn run(args: InfoArgs) -> anyhow::Result<ExitCode> {
    let is_scene = args.file.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml"));
    let is_image = args.file.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    anyhow::ensure!(
        is_image || (args.patch.is_none() && args.against.is_none()),
        "--patch and --against are for OpenEXR images"
    );
    let text = if is_image {
        crate::image_stats::image_info(&args.file, args.patch, args.against.as_deref())?
    } else if englobe_scene::pbrt::is_pbrt_path(&args.file) {
        scene_info(&args.file, &englobe_scene::pbrt::load(&args.file, args.strict)?)
    } else if is_scene {
        scene_info(&args.file, &load_scene(&args.file)?)
    } else {
        // The file as it is: no normals generated (its vertex count stays the file's).
        mesh_info(
            &args.file,
            &load_mesh_file_with(&args.file, &MeshOptions { smooth_angle: 0.0, want_tangents: false })?,
        )
    };
    print!("{text}");
    Ok(ExitCode::SUCCESS)
}

fn bounds_lines(out: &mut String, b: &Aabb) {
    if b.is_empty() {
        let _ = writeln!(out, "bounds:     (empty)");
    } else {
        let _ = writeln!(out, "bounds:     min {} max {}", b.min, b.max);
        let _ = writeln!(out, "size:       {}", b.extent());
    }
}

fn warnings_lines(out: &mut String, warnings: &[String]) {
    let _ = writeln!(out, "warnings:   {}", warnings.len());
    for w in warnings {
        let _ = writeln!(out, "  - {w}");
    }
}

/// The description of a loaded mesh file.
pub fn mesh_info(path: &Path, m: &LoadedMesh) -> String {
    let mut out = String::new();
    let mesh = &m.mesh;
    let _ = writeln!(out, "file:       {}", path.display());
    let _ = writeln!(out, "format:     {}", m.format.name());
    let _ = writeln!(out, "triangles:  {}", mesh.len());
    let _ = writeln!(out, "vertices:   {}", mesh.positions().len());
    let yes = |b: bool| if b { "yes" } else { "no" };
    let normals = if mesh.normals().is_some() {
        "yes".to_owned()
    } else {
        format!(
            "no (a scene smooths them within {DEFAULT_SMOOTH_ANGLE} degrees unless its `smooth_angle` says otherwise)"
        )
    };
    let _ = writeln!(out, "normals:    {normals}");
    let _ = writeln!(out, "uvs:        {}", uv_sets_text(mesh));
    let _ = writeln!(out, "tangents:   {}", yes(m.tangents.is_some()));
    bounds_lines(&mut out, &mesh.bounds());
    let _ = writeln!(out, "memory:     {} bytes (vertices, triangles and attributes)", mesh_bytes(mesh));
    let _ = writeln!(out, "materials:  {}", m.materials.len());
    for (i, (name, mat)) in m.materials.iter().enumerate() {
        let used = m.triangle_materials.as_ref().map_or(0, |ids| ids.iter().filter(|&&id| id == i as u32).count());
        let _ = writeln!(out, "  - {name}: {}, {used} triangles", material_text(mat, &m.textures));
    }
    textures_lines(&mut out, &m.textures, m.materials.iter().map(|(n, m)| (n.as_str(), m)));
    warnings_lines(&mut out, &m.warnings);
    out
}

/// The texture coordinate sets a mesh keeps: `no`, `yes (set 0)`, `yes (sets 0, 1)`.
fn uv_sets_text(mesh: &TriangleMesh) -> String {
    let sets: Vec<String> = (0..2).filter(|&s| mesh.uv_set(s).is_some()).map(|s| s.to_string()).collect();
    match sets.len() {
        0 => "no".to_owned(),
        1 => format!("yes (set {})", sets[0]),
        _ => format!("yes (sets {})", sets.join(", ")),
    }
}

/// A material's model, factors and texture slots on one line.
fn material_text(m: &Material, textures: &[std::sync::Arc<Texture>]) -> String {
    let mut s = match m.model {
        MaterialModel::Classic => format!(
            "classic, diffuse {}, specular {}, shininess {}, reflectivity {}, transparency {}, ior {}",
            m.diffuse, m.specular, m.shininess, m.reflectivity, m.transparency, m.ior
        ),
        MaterialModel::MetallicRoughness { metallic, roughness, transmission } => format!(
            "metallic_roughness, base colour {}, metallic {metallic}, roughness {roughness}, transmission {transmission}, ior {}",
            m.diffuse, m.ior
        ),
        MaterialModel::Conductor { eta, k, alpha } => format!("conductor, eta {eta}, k {k}, alpha {alpha}"),
        MaterialModel::Dielectric { alpha } => format!("dielectric, ior {}, alpha {alpha}", m.ior),
        MaterialModel::CoatedDiffuse { alpha } => {
            format!("coated_diffuse, reflectance {}, coat ior {}, alpha {alpha}", m.diffuse, m.ior)
        }
    };
    if m.emission != englobe::Vec3::ZERO {
        let _ = write!(s, ", emission {}", m.emission);
    }
    match m.alpha.mode {
        englobe_scene::AlphaMode::Opaque => {}
        englobe_scene::AlphaMode::Mask { cutoff } => {
            let _ = write!(s, ", alpha mask {} (cutoff {cutoff})", m.alpha.factor);
        }
        englobe_scene::AlphaMode::Blend => {
            let _ = write!(s, ", alpha blend {}", m.alpha.factor);
        }
    }
    if !m.double_sided {
        s += ", single-sided";
    }
    for (slot, r) in m.textures.slots() {
        let name = textures.get(r.texture as usize).map_or("(missing)", |t| t.name.as_str());
        let _ = write!(s, ", {slot} texture {name}");
        if r.uv_set != 0 {
            let _ = write!(s, " (uv set {})", r.uv_set);
        }
    }
    s
}

/// The textures, each with its size and the material slots that use it, or why it could not be
/// read.
fn textures_lines<'a>(
    out: &mut String,
    textures: &[std::sync::Arc<Texture>],
    materials: impl Iterator<Item = (&'a str, &'a Material)>,
) {
    let mut uses: Vec<Vec<String>> = vec![Vec::new(); textures.len()];
    for (name, m) in materials {
        for (slot, r) in m.textures.slots() {
            if let Some(u) = uses.get_mut(r.texture as usize) {
                u.push(format!("{name} {slot}"));
            }
        }
    }
    let unreadable = textures.iter().filter(|t| t.image.is_none()).count();
    let _ = writeln!(out, "textures:   {} ({unreadable} unreadable)", textures.len());
    for (t, used) in textures.iter().zip(&uses) {
        let what = match (&t.image, &t.error) {
            (Some(i), _) => format!("{}x{}, {} channels, {} bits", i.width(), i.height(), i.channels(), i.bits()),
            (None, e) => format!("UNREADABLE: {}", e.as_deref().unwrap_or("unknown")),
        };
        let _ = writeln!(
            out,
            "  - {} ({}): {what}; used as {}",
            t.name,
            t.source,
            if used.is_empty() { "nothing".into() } else { used.join(", ") }
        );
    }
}

/// Bytes held by a mesh's arrays.
pub fn mesh_bytes(m: &TriangleMesh) -> usize {
    std::mem::size_of_val(m.positions())
        + std::mem::size_of_val(m.triangles())
        + m.normals().map_or(0, std::mem::size_of_val)
        + m.uvs().map_or(0, std::mem::size_of_val)
        + m.uvs1().map_or(0, std::mem::size_of_val)
}

/// The description of a loaded scene.
pub fn scene_info(path: &Path, scene: &Scene) -> String {
    let mut out = String::new();
    let (mut spheres, mut planes, mut boxes, mut triangles, mut meshes, mut instances) = (0, 0, 0, 0, 0, 0);
    let mut shown_triangles = 0usize;
    let mut distinct: HashSet<*const TriangleMesh> = HashSet::new();
    let (mut stored_triangles, mut stored_bytes) = (0usize, 0usize);
    let mut bounds = Aabb::EMPTY;
    for o in &scene.objects {
        shown_triangles += o.object.triangle_count();
        let mesh = match &o.object {
            Object::Shape(s) => {
                match s {
                    Shape::Sphere(_) => spheres += 1,
                    Shape::Plane(_) => planes += 1,
                    Shape::AaBox(_) => boxes += 1,
                    Shape::Triangle(_) => triangles += 1,
                }
                if s.is_bounded() {
                    bounds = bounds.union(&s.bounds());
                }
                None
            }
            Object::Mesh(m) => {
                meshes += 1;
                bounds = bounds.union(&m.bounds());
                Some(m)
            }
            Object::Instance(i) => {
                instances += 1;
                bounds = bounds.union(&i.bounds());
                Some(i.mesh())
            }
        };
        if let Some(m) = mesh
            && distinct.insert(std::sync::Arc::as_ptr(m))
        {
            stored_triangles += m.len();
            stored_bytes += mesh_bytes(m);
        }
    }
    let _ = writeln!(out, "file:       {}", path.display());
    let _ = writeln!(
        out,
        "image:      {}x{}, {} spp, depth {}",
        scene.image.width, scene.image.height, scene.image.samples, scene.image.max_depth
    );
    let _ = writeln!(
        out,
        "integrator: {}, filter {} of radius {}",
        scene.image.integrator.name(),
        scene.image.filter.name(),
        scene.image.filter.radius()
    );
    let c = &scene.camera;
    let _ = writeln!(
        out,
        "camera:     at {} looking at {}, up {}, vertical fov {}{}",
        c.position,
        c.look_at,
        c.up,
        c.fov_degrees,
        if c.left_handed { " (left-handed, as pbrt)" } else { "" }
    );
    let _ = writeln!(out, "lights:     {}", scene.lights.len());
    let _ = writeln!(out, "objects:    {}", scene.objects.len());
    let _ = writeln!(
        out,
        "  spheres {spheres}, planes {planes}, boxes {boxes}, triangles {triangles}, meshes {meshes}, instances {instances}"
    );
    let _ = writeln!(out, "triangles:  {shown_triangles} in the picture, {stored_triangles} stored");
    let _ = writeln!(out, "meshes:     {} distinct, {stored_bytes} bytes of mesh data", distinct.len());
    bounds_lines(&mut out, &bounds);
    let _ = writeln!(out, "materials:  {}", scene.materials.len());
    for (name, mat) in scene.material_names.iter().zip(&scene.materials) {
        let _ = writeln!(out, "  - {name}: {}", material_text(mat, &scene.textures));
    }
    textures_lines(&mut out, &scene.textures, scene.material_names.iter().map(String::as_str).zip(&scene.materials));
    warnings_lines(&mut out, &scene.warnings);
    out
}

#[cfg(test)]
mod tests {
    use englobe::{Vec2, Vec3};

    use super::*;

    #[test]
    fn the_uvs_line_names_the_sets() {
        let tri = TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]).unwrap();
        assert_eq!(uv_sets_text(&tri), "no");
        let one = tri.clone().with_uvs(vec![Vec2::ZERO; 3]).unwrap();
        assert_eq!(uv_sets_text(&one), "yes (set 0)");
        let two = one.clone().with_uvs1(vec![Vec2::ONE; 3]).unwrap();
        assert_eq!(uv_sets_text(&two), "yes (sets 0, 1)");
        assert_eq!(mesh_bytes(&two), mesh_bytes(&one) + 3 * std::mem::size_of::<Vec2>());
    }
}
