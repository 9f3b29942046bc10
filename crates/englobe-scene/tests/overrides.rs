//! Overrides from the command line (`-D key=value`) change the scene exactly as an edit of the file
//! would, and a wrong key or value is reported against the override that wrote it.

use englobe_scene::{Light, Override, Scene, SceneError, parse_scene, parse_scene_with};

const SCENE: &str = r#"
[image]
width = 64
height = 48

[camera]
position = [0, 1, -5]
look_at = [0, 1, 0]

[materials.red]
diffuse = [0.8, 0.1, 0.1]

[[point_light]]
position = [2, 4, -3]
intensity = 10

[[point_light]]
position = [-2, 4, -3]
intensity = 5

[[sphere]]
center = [0, 1, 0]
radius = 1
material = "red"
"#;

fn with(overrides: &[&str]) -> Result<Scene, SceneError> {
    let overrides: Vec<Override> = overrides.iter().map(|o| o.parse().unwrap()).collect();
    parse_scene_with(SCENE, "s.toml".as_ref(), &overrides)
}

fn power(scene: &Scene, i: usize) -> f32 {
    match scene.lights[i] {
        Light::Point { power, .. } => power.x,
        _ => panic!("light {i} is not a point light"),
    }
}

#[test]
fn nested_keys_and_array_entries_are_overridden() {
    let s =
        with(&["camera.fov=40", "point_light.1.intensity=60", "image.samples=64", "materials.red.diffuse=[0, 1, 0]"])
            .unwrap();
    assert_eq!(s.camera.fov_degrees, 40.0);
    assert_eq!((power(&s, 0), power(&s, 1)), (10.0, 60.0));
    assert_eq!(s.image.samples, 64);
    assert_eq!(s.materials[1].diffuse, englobe::Vec3::new(0.0, 1.0, 0.0));
}

#[test]
fn an_index_one_past_the_end_adds_an_entry() {
    let s = with(&["point_light.2.position=[0, 9, 0]", "point_light.2.intensity=3"]).unwrap();
    assert_eq!(s.lights.len(), 3);
    assert_eq!(power(&s, 2), 3.0);
    let s = with(&["sphere.1={center = [3, 1, 0], radius = 0.5}"]).unwrap();
    assert_eq!(s.objects.len(), parse_scene(SCENE, "s.toml".as_ref()).unwrap().objects.len() + 1);
}

#[test]
fn a_bare_word_is_a_string() {
    let s = with(&["image.integrator=path"]).unwrap();
    assert_eq!(s.image.integrator, englobe_scene::IntegratorKind::Path);
}

fn error(overrides: &[&str]) -> String {
    match with(overrides) {
        Ok(_) => panic!("{overrides:?} must be refused"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn a_bad_value_names_the_override_and_its_column() {
    let e = error(&["image.samples=64", "camera.fov=400"]);
    assert!(e.starts_with("-D camera.fov=400:1:15: a field of view of 400 degrees"), "{e}");
    let e = error(&["image.width=\"wide\""]);
    assert!(e.starts_with("-D image.width=\"wide\":1:16: invalid type: string"), "{e}");
    let e = error(&["camera.fov=[1, 2"]);
    assert!(e.starts_with("-D camera.fov=[1, 2:1:"), "{e}");
}

#[test]
fn an_unknown_key_names_the_override() {
    let e = error(&["camera.foo=1"]);
    assert!(e.starts_with("-D camera.foo=1:1:11: unknown field `foo`"), "{e}");
    let e = error(&["lamp.intensity=1"]);
    assert!(e.starts_with("-D lamp.intensity=1:1:4: unknown field `lamp`"), "{e}");
}

#[test]
fn a_bad_path_says_what_is_there() {
    let e = error(&["point_light.5.intensity=1"]);
    assert!(e.starts_with("-D point_light.5.intensity=1:1:16: `point_light` has 2 entries: `5` is not an index (expected 0 to 1, or 2 to add one)"), "{e}");
    let e = error(&["image.width.x=1"]);
    assert!(e.contains("`width` is an integer, so it has no `x`"), "{e}");
}

#[test]
fn errors_in_the_file_keep_their_place() {
    let overrides: Vec<Override> = vec!["camera.fov=40".parse().unwrap()];
    let bad = SCENE.replace("radius = 1", "radius = -1");
    let e = parse_scene_with(&bad, "s.toml".as_ref(), &overrides).unwrap_err().to_string();
    assert!(e.starts_with("s.toml:23:10:"), "{e}");
}
