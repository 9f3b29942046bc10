//! A digest of everything that decides an image's pixels: the scene (camera, lights, materials,
//! textures, every object with every vertex of its meshes) and the options of the render. Tiles record it,
//! so that assembly can refuse pieces of different renders (see [`crate::tile`]).
//!
//! The scene's image settings include its pixel filter and its camera the camera's handedness,
//! so both enter the digest with the rest.
//!
//! The hash is BLAKE3 (O'Connor, Aumasson, Neves and Wilcox-O'Hearn, 2020): fast enough that
//! hashing a mesh costs less than loading it. Meshes are hashed by their numbers' bits, shared
//! meshes once per instance reference; the small parts of the scene by their `Debug` text, which
//! prints every `f32` exactly (shortest round-trip form).

use std::collections::HashMap;
use std::sync::Arc;

use englobe::{Object, TriangleMesh};
use englobe_scene::{Environment, ImageSettings, Scene, Sky};

/// The digest of `scene` rendered with `options` (anything else that changes the pixels, such as
/// the acceleration structure's name and what the image shows), as 64 hexadecimal digits.
/// The scene's warnings are left out: they describe the loading, not the picture.
pub fn scene_digest(scene: &Scene, options: &str) -> String {
    let mut h = blake3::Hasher::new();
    let mut text = |label: &str, value: String| {
        h.update(label.as_bytes());
        h.update(&(value.len() as u64).to_le_bytes());
        h.update(value.as_bytes());
    };
    text("options", options.to_owned());
    // How the image is written (exposure, tone map, half floats) changes no linear pixel: tiles of
    // one render written differently still assemble.
    let image = ImageSettings { output: Default::default(), ..scene.image.clone() };
    text("image", format!("{image:?}"));
    text("camera", format!("{:?}", scene.camera));
    text("lights", format!("{:?}", scene.lights));
    text("materials", format!("{:?}", scene.materials));
    text("material names", format!("{:?}", scene.material_names));
    // A texture's `Debug` names its source and sampler and carries its texels' hash.
    text("textures", format!("{:?}", scene.textures));
    // The map's Debug text names only its file: its pixels are hashed by their bits.
    text("environment", format!("{:?}", scene.environment));
    if let Some(Environment { sky: Sky::Map(map), .. }) = &scene.environment {
        h.update(&map.width.to_le_bytes());
        h.update(&map.height.to_le_bytes());
        for p in &map.pixels {
            for c in p.to_array() {
                h.update(&c.to_bits().to_le_bytes());
            }
        }
    }
    let mut meshes: HashMap<*const TriangleMesh, [u8; 32]> = HashMap::new();
    let mut mesh_digest =
        |mesh: &Arc<TriangleMesh>| *meshes.entry(Arc::as_ptr(mesh)).or_insert_with(|| hash_mesh(mesh));
    for (i, o) in scene.objects.iter().enumerate() {
        h.update(b"object");
        h.update(&(i as u64).to_le_bytes());
        h.update(&o.material.to_le_bytes());
        match &o.object {
            Object::Shape(s) => {
                h.update(format!("shape {s:?}").as_bytes());
            }
            Object::Mesh(m) => {
                h.update(b"mesh");
                h.update(&mesh_digest(m));
            }
            Object::Instance(inst) => {
                h.update(format!("instance {:?}", inst.to_world()).as_bytes());
                h.update(&mesh_digest(inst.mesh()));
            }
        }
        match &o.triangle_materials {
            Some(ids) => {
                h.update(&(ids.len() as u64).to_le_bytes());
                for id in ids.iter() {
                    h.update(&id.to_le_bytes());
                }
            }
            None => {
                h.update(b"one material");
            }
        }
    }
    h.finalize().to_hex().to_string()
}

/// The digest of one mesh's positions, triangles, normals and texture coordinates (both sets),
/// bit for bit.
fn hash_mesh(mesh: &TriangleMesh) -> [u8; 32] {
    let mut h = blake3::Hasher::new();
    let mut floats = |label: &[u8], values: &mut dyn Iterator<Item = f32>| {
        h.update(label);
        let mut n = 0u64;
        for v in values {
            h.update(&v.to_bits().to_le_bytes());
            n += 1;
        }
        h.update(&n.to_le_bytes());
    };
    floats(b"positions", &mut mesh.positions().iter().flat_map(|p| p.to_array()));
    if let Some(normals) = mesh.normals() {
        floats(b"normals", &mut normals.iter().flat_map(|p| p.to_array()));
    }
    if let Some(uvs) = mesh.uvs() {
        floats(b"uvs", &mut uvs.iter().flat_map(|p| p.to_array()));
    }
    if let Some(uvs) = mesh.uvs1() {
        floats(b"uvs1", &mut uvs.iter().flat_map(|p| p.to_array()));
    }
    h.update(b"triangles");
    for t in mesh.triangles() {
        for i in t {
            h.update(&i.to_le_bytes());
        }
    }
    *h.finalize().as_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;
    use englobe::{Sphere, Vec3};
    use englobe_scene::SceneObject;

    fn scene() -> Scene {
        englobe_scene::parse_scene(crate::DEFAULT_SCENE, "default.toml".as_ref()).unwrap()
    }

    #[test]
    fn same_scene_same_digest_and_any_change_shows() {
        let base = scene_digest(&scene(), "accel=bvh-wide");
        assert_eq!(base.len(), 64);
        assert_eq!(base, scene_digest(&scene(), "accel=bvh-wide"));
        assert_ne!(base, scene_digest(&scene(), "accel=none"));
        let mut s = scene();
        s.image.samples += 1;
        assert_ne!(base, scene_digest(&s, "accel=bvh-wide"));
        let mut s = scene();
        s.image.noise_threshold = 0.01;
        assert_ne!(base, scene_digest(&s, "accel=bvh-wide"), "adaptive sampling changes the pixels");
        s.image.min_samples = Some(8);
        assert_ne!(scene_digest(&s, "accel=bvh-wide"), {
            let mut t = scene();
            t.image.noise_threshold = 0.01;
            scene_digest(&t, "accel=bvh-wide")
        });
        let mut s = scene();
        s.camera.fov_degrees = f32::from_bits(s.camera.fov_degrees.to_bits() + 1);
        assert_ne!(base, scene_digest(&s, "accel=bvh-wide"), "one bit of one number");
        let mut s = scene();
        s.objects.push(SceneObject::new(Sphere::new(Vec3::ZERO, 1.0).into(), 0));
        assert_ne!(base, scene_digest(&s, "accel=bvh-wide"));
        let mut s = scene();
        s.image.clamp = Some(10.0);
        assert_ne!(base, scene_digest(&s, "accel=bvh-wide"), "the clamp changes pixels");
        let mut s = scene();
        s.image.output.exposure = 2.0;
        s.image.output.tonemap = englobe_scene::ToneMap::Filmic;
        s.image.output.exr_half = true;
        assert_eq!(base, scene_digest(&s, "accel=bvh-wide"), "how the image is written changes no pixel");
        let mut s = scene();
        s.image.filter = englobe_scene::PixelFilter::Triangle { radius: englobe::Vec2::splat(1.0) };
        assert_ne!(base, scene_digest(&s, "accel=bvh-wide"), "the pixel filter changes the pixels");
        let mut s = scene();
        s.camera.left_handed = true;
        assert_ne!(base, scene_digest(&s, "accel=bvh-wide"), "a mirrored camera changes the pixels");
        let mut s = scene();
        s.warnings.push("a warning changes nothing in the picture".into());
        assert_eq!(base, scene_digest(&s, "accel=bvh-wide"));
    }

    #[test]
    fn one_vertex_moved_changes_the_digest() {
        let mesh = |z: f32| {
            let m = TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::new(0.0, 1.0, z)], vec![[0, 1, 2]]).unwrap();
            let mut s = scene();
            s.objects.push(SceneObject::new(m.into(), 0));
            scene_digest(&s, "")
        };
        assert_eq!(mesh(0.0), mesh(0.0));
        assert_ne!(mesh(0.0), mesh(-0.0));
    }
}

#[cfg(test)]
mod environment_tests {
    use std::sync::Arc;

    use englobe::Vec3;
    use englobe_scene::EnvironmentMap;

    use super::*;

    #[test]
    fn one_pixel_of_the_environment_map_changes_the_digest() {
        let with = |value: f32| {
            let mut s = englobe_scene::parse_scene(crate::DEFAULT_SCENE, "default.toml".as_ref()).unwrap();
            let mut pixels = vec![Vec3::ONE; 8];
            pixels[5].y = value;
            let map = EnvironmentMap { path: "same-name.exr".into(), width: 4, height: 2, pixels };
            s.environment = Some(Environment { sky: Sky::Map(Arc::new(map)), intensity: 1.0, rotation_degrees: 0.0 });
            scene_digest(&s, "")
        };
        assert_eq!(with(1.0), with(1.0));
        assert_ne!(with(1.0), with(f32::from_bits(1.0f32.to_bits() + 1)));
    }
}
