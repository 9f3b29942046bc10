//! Every kind of bad scene is refused with an error naming the file, the line and the column of
//! the offending value, and saying what was expected.

use englobe_scene::{Located, SceneError, parse_scene};

const GOOD: &str = r#"
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

[[sphere]]
center = [0, 1, 0]
radius = 1
material = "red"
"#;

/// Parses `text` and returns the located error it must produce.
fn error_of(text: &str) -> Located {
    match parse_scene(text, "bad.toml".as_ref()) {
        Ok(_) => panic!("the scene was accepted:\n{text}"),
        Err(SceneError::Invalid(l)) => l,
        Err(e) => panic!("unexpected error kind: {e}"),
    }
}

/// The 1-based line and column of byte `offset` of `text`.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let line = text[..offset].matches('\n').count() + 1;
    let column = offset - text[..offset].rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, column)
}

/// Replaces `from` by `to` in the good scene and expects an error whose message contains
/// `expected`, located at the first occurrence of `at` inside the replacement, or in the whole
/// text when `at` is not part of the replacement (a table header, say).
fn check(from: &str, to: &str, at: &str, expected: &str) {
    let start = GOOD.find(from).unwrap_or_else(|| panic!("`{from}` not in the good scene"));
    let text = GOOD.replacen(from, to, 1);
    let offset = match to.find(at) {
        Some(i) => start + i,
        None => text.find(at).unwrap_or_else(|| panic!("`{at}` not in the scene")),
    };
    let e = error_of(&text);
    assert_eq!(e.file, "bad.toml");
    assert_eq!((e.line, e.column), line_column(&text, offset), "wrong place for {to:?}: {e}");
    assert!(e.message.contains(expected), "message {:?} does not say {expected:?}", e.message);
    let shown = e.to_string();
    assert!(shown.starts_with(&format!("bad.toml:{}:{}: ", e.line, e.column)), "{shown}");
}

#[test]
fn the_good_scene_is_accepted() {
    let s = parse_scene(GOOD, "good.toml".as_ref()).unwrap();
    assert_eq!((s.image.width, s.image.height, s.objects.len(), s.lights.len()), (64, 48, 1, 1));
    assert_eq!(s.material_names, ["default", "red"]);
}

#[test]
fn unknown_keys() {
    check("radius = 1", "radius = 1\ncolour = 3", "colour", "unknown field `colour`");
    check("[image]", "[image]\nwdth = 3", "wdth", "unknown field `wdth`");
    check("[[sphere]]", "[[sphere]]\nmass = 1", "mass", "unknown field");
    check("[[sphere]]", "[[spheres]]", "spheres", "unknown field `spheres`");
}

#[test]
fn missing_required_keys() {
    check("radius = 1\n", "", "[[sphere]]", "missing field `radius`");
    check("width = 64\n", "", "[image]", "missing field `width`");
    check("look_at = [0, 1, 0]\n", "", "[camera]", "missing field `look_at`");
    let e = error_of(&GOOD.replacen("[camera]", "[not_camera]", 1));
    assert!(e.message.contains("unknown field `not_camera`"), "{}", e.message);
}

#[test]
fn wrong_types() {
    check("radius = 1", "radius = \"one\"", "\"one\"", "expected f64");
    check("width = 64", "width = 64.5", "64.5", "expected u32");
    check("center = [0, 1, 0]", "center = [0, 1]", "[0, 1]", "expected an array of length 3");
    check("material = \"red\"", "material = 3", "3\n", "expected a string");
    check("width = 64", "width = -64", "-64", "expected u32");
    check("width = 64", "width = 64\nmax_depth = -1", "-1", "expected u32");
    check("width = 64", "width = 64\nsamples = 1e9", "1e9", "expected u32");
}

#[test]
fn unknown_material() {
    check("material = \"red\"", "material = \"blue\"", "\"blue\"", "unknown material `blue`");
    let e = error_of(&GOOD.replacen("material = \"red\"", "material = \"blue\"", 1));
    assert!(e.message.contains("default, red"), "lists the known materials: {}", e.message);
}

#[test]
fn zero_and_negative_radius() {
    check("radius = 1", "radius = 0", "0", "greater than 0");
    check("radius = 1", "radius = -2.5", "-2.5", "greater than 0");
}

#[test]
fn degenerate_camera() {
    check("look_at = [0, 1, 0]", "look_at = [0, 1, -5]", "[0, 1, -5]", "must differ from its position");
    check("look_at = [0, 1, 0]", "look_at = [0, 1, 0]\nup = [0, 0, 2]", "[0, 0, 2]", "parallel");
    check("look_at = [0, 1, 0]", "look_at = [0, 1, 0]\nup = [0, 0, 0]", "[0, 0, 0]", "zero or parallel");
    check("look_at = [0, 1, 0]", "look_at = [0, 1, 0]\nfov = 180", "180", "less than 180");
    check("look_at = [0, 1, 0]", "fov = 0\nlook_at = [0, 1, 0]", "0", "more than 0");
}

#[test]
fn non_finite_numbers() {
    check("radius = 1", "radius = nan", "nan", "finite");
    check("radius = 1", "radius = inf", "inf", "finite");
    // An error inside a vector points at the vector.
    check("center = [0, 1, 0]", "center = [0, -inf, 0]", "[", "finite");
    check("intensity = 10", "intensity = nan", "nan", "finite");
    check("center = [0, 1, 0]", "center = [0, 1e39, 0]", "[", "32-bit float");
}

#[test]
fn image_limits() {
    check("width = 64", "width = 0", "0", "at least 1");
    check("height = 48", "height = 0", "0", "at least 1");
    check("width = 64", "width = 10000000", "10000000", "more than the limit");
    check("width = 64", "width = 64\nsamples = 0", "[image]", "samples per pixel");
    check("width = 64", "width = 64\nmax_depth = 1000", "[image]", "maximum depth");
    check("width = 64", "width = 64\nnoise_threshold = -0.1", "-0.1", "at least 0");
    check("width = 64", "width = 64\nmin_samples = 1", "1", "expected 2 to 65536");
    check("width = 64", "width = 64\nmin_samples = 100000", "100000", "expected 2 to 65536");
}

#[test]
fn adaptive_sampling_keys() {
    let plain = parse_scene(GOOD, "good.toml".as_ref()).unwrap();
    assert_eq!((plain.image.noise_threshold, plain.image.min_samples), (0.0, None), "off by default");
    let text = GOOD.replacen("width = 64", "width = 64\nnoise_threshold = 0.02\nmin_samples = 8", 1);
    let s = parse_scene(&text, "good.toml".as_ref()).unwrap();
    assert_eq!((s.image.noise_threshold, s.image.min_samples), (0.02, Some(8)));
}

#[test]
fn pixel_filters_are_checked() {
    check("width = 64", "width = 64\nfilter = \"mitchell\"", "\"mitchell\"", "unknown filter `mitchell`");
    check("width = 64", "width = 64\nfilter = \"box\"\nfilter_sigma = 0.5", "0.5", "`filter_sigma` is for");
    check("width = 64", "width = 64\nfilter = \"triangle\"\nfilter_radius = 0", "0", "more than 0");
    check("width = 64", "width = 64\nfilter_radius = [1, 17]", "[1, 17]", "at most 16");
    check("width = 64", "width = 64\nfilter = \"gaussian\"\nfilter_sigma = -1", "-1", "greater than 0");
    let filter = |keys: &str| {
        parse_scene(&GOOD.replacen("width = 64", &format!("width = 64\n{keys}"), 1), "f.toml".as_ref())
            .unwrap()
            .image
            .filter
    };
    use englobe::Vec2;
    use englobe_scene::PixelFilter;
    assert_eq!(filter(""), PixelFilter::Box { radius: Vec2::splat(0.5) });
    assert_eq!(filter("filter = \"triangle\""), PixelFilter::Triangle { radius: Vec2::splat(2.0) });
    assert_eq!(
        filter("filter = \"gaussian\"\nfilter_radius = [2, 1]\nfilter_sigma = 0.25"),
        PixelFilter::Gaussian { radius: Vec2::new(2.0, 1.0), sigma: 0.25 }
    );
}

#[test]
fn other_checked_values() {
    check("[[sphere]]", "[[plane]]\npoint = [0,0,0]\nnormal = [0,0,0]\n[[sphere]]", "[0,0,0]\n[[", "non-zero normal");
    check("[[sphere]]", "[[box]]\nmin = [0,0,0]\nmax = [1,0,1]\n[[sphere]]", "[[box]]", "min < max");
    check(
        "[[sphere]]",
        "[[triangle]]\nvertices = [[0,0,0],[1,1,1],[2,2,2]]\n[[sphere]]",
        "[[triangle]]",
        "area is zero",
    );
    check("diffuse = [0.8, 0.1, 0.1]", "diffuse = [0.8, -0.1, 0.1]", "[", "at least 0");
    check("diffuse = [0.8, 0.1, 0.1]", "reflectivity = 1.5", "1.5", "between 0 and 1");
    check("diffuse = [0.8, 0.1, 0.1]", "reflectivity = 0.6\ntransparency = 0.6", "[materials.red]", "at most 1");
    check(
        "[[sphere]]",
        "[[sphere_grid]]\norigin = [0,0,0]\nspacing = [1,1,1]\ncounts = [100000, 100000, 1]\nradius = 0.1\n[[sphere]]",
        "[[sphere_grid]]",
        "over the limit",
    );
}

#[test]
fn syntax_errors_are_located() {
    let text = GOOD.replacen("width = 64", "width = = 64", 1);
    let e = error_of(&text);
    assert_eq!(e.line, line_column(&text, text.find("width").unwrap()).0);
}

#[test]
fn sphere_grid_expands_in_order() {
    let text = GOOD.replacen(
        "[[sphere]]",
        "[[sphere_grid]]\norigin = [0,0,10]\nspacing = [1,2,3]\ncounts = [3,2,1]\nradius = 0.25\n[[sphere]]",
        1,
    );
    let s = parse_scene(&text, "grid.toml".as_ref()).unwrap();
    assert_eq!(s.objects.len(), 7);
    let englobe::Object::Shape(englobe::Shape::Sphere(last)) = &s.objects[6].object else { panic!() };
    assert_eq!(last.center, englobe::Vec3::new(2.0, 2.0, 10.0));
}

#[test]
fn random_triangles_are_checked_and_generated() {
    let entry = |body: &str| format!("[[random_triangles]]\n{body}\n[[sphere]]");
    check("[[sphere]]", &entry("count = 0\nmin = [0,0,0]\nmax = [1,1,1]\nsize = 0.1"), "0\n", "expected 1 to");
    check(
        "[[sphere]]",
        &entry("count = 20000000\nmin = [0,0,0]\nmax = [1,1,1]\nsize = 0.1"),
        "20000000",
        "expected 1 to 16777216",
    );
    check(
        "[[sphere]]",
        &entry("count = 10\nmin = [0,2,0]\nmax = [1,1,1]\nsize = 0.1"),
        "[[random_triangles]]",
        "min <= max",
    );
    check("[[sphere]]", &entry("count = 10\nmin = [0,0,0]\nmax = [1,1,1]\nsize = -1"), "-1", "greater than 0");
    check(
        "[[sphere]]",
        &entry("count = 10\nmin = [0,0,0]\nmax = [1,1,1]\nsize = 1\nsides = 3"),
        "sides",
        "unknown field",
    );

    let text = GOOD.replacen(
        "[[sphere]]",
        &entry("count = 500\nmin = [-1,-1,-1]\nmax = [1,1,1]\nsize = 0.2\nseed = 9\nmaterial = \"red\""),
        1,
    );
    let s = parse_scene(&text, "soup.toml".as_ref()).unwrap();
    let again = parse_scene(&text, "soup.toml".as_ref()).unwrap();
    // After the sphere (spheres come first), one mesh of 500 triangles, the same every time.
    assert_eq!(s.objects.len(), 2);
    let englobe::Object::Mesh(mesh) = &s.objects[1].object else { panic!("a mesh") };
    assert_eq!(mesh.len(), 500);
    assert_eq!(s.objects[1].material, 1);
    assert_eq!(s.objects, again.objects);
}

#[test]
fn material_model_keys() {
    let red = "diffuse = [0.8, 0.1, 0.1]";
    check(
        red,
        "diffuse = [0.8, 0.1, 0.1]\nmetallic = 0.5",
        "0.5",
        "`metallic` belongs to `model = \"metallic_roughness\"`",
    );
    check(red, "diffuse = [0.8, 0.1, 0.1]\nroughness = 0.2", "0.2", "`roughness` belongs to");
    check(red, "diffuse = [0.8, 0.1, 0.1]\nbase_color = [1, 1, 1]", "[1, 1, 1]", "`base_color` and `diffuse`");
    check(red, "diffuse = [0.8, 0.1, 0.1]\nalpha_cutoff = 0.3", "0.3", "needs `alpha_mode = \"mask\"`");
    check(red, "model = \"pbr\"", "\"pbr\"", "unknown variant `pbr`");
    check(red, "model = \"metallic_roughness\"\nmetallic = 1.5", "1.5", "between 0 and 1");
    check(red, "alpha_mode = \"cutout\"", "\"cutout\"", "unknown variant `cutout`");
    check(red, "texture_wrap = \"clamp\"", "\"clamp\"", "unknown variant `clamp`");
    check(red, "base_color_texture = 3", "3", "expected a string");
}

#[test]
fn metallic_roughness_materials_and_their_defaults() {
    let text = GOOD.replacen(
        "diffuse = [0.8, 0.1, 0.1]",
        "model = \"metallic_roughness\"\nbase_color = [0.8, 0.1, 0.1]\nroughness = 0.25\nemission = [1, 0.5, 0]\n\
         emission_strength = 2\nalpha_mode = \"mask\"\ndouble_sided = false\nbase_color_texture = \"nowhere.png\"",
        1,
    );
    let s = parse_scene(&text, "good.toml".as_ref()).unwrap();
    let m = &s.materials[1];
    assert_eq!(
        m.model,
        englobe_scene::MaterialModel::MetallicRoughness { metallic: 1.0, roughness: 0.25, transmission: 0.0 }
    );
    assert_eq!((m.diffuse, m.emission), (englobe::Vec3::new(0.8, 0.1, 0.1), englobe::Vec3::new(2.0, 1.0, 0.0)));
    assert_eq!((m.alpha.mode, m.double_sided), (englobe_scene::AlphaMode::Mask { cutoff: 0.5 }, false));
    // The missing texture is a warning and a texture without an image, not an error.
    assert_eq!(s.textures.len(), 1);
    assert!(s.textures[0].image.is_none());
    assert!(s.warnings[0].contains("material `red`") && s.warnings[0].contains("nowhere.png"), "{:?}", s.warnings);
    // The classic default is unchanged.
    let d = &s.materials[0];
    assert_eq!(
        (d.model, d.double_sided, d.alpha.mode),
        (englobe_scene::MaterialModel::Classic, true, englobe_scene::AlphaMode::Opaque)
    );
}

#[test]
fn rectangles_and_output_settings_are_checked() {
    let flat = format!("{GOOD}\n[[rectangle]]\ncorner = [0, 0, 0]\nedge1 = [1, 0, 0]\nedge2 = [2, 0, 0]\n");
    let e = error_of(&flat);
    assert_eq!(e.line, flat.lines().position(|l| l == "[[rectangle]]").unwrap() + 1, "{e}");
    assert!(e.message.contains("not parallel"), "{e}");
    let good = format!("{GOOD}\n[[rectangle]]\ncorner = [0, 0, 0]\nedge1 = [1, 0, 0]\nedge2 = [0, 0, 2]\n");
    let s = parse_scene(&good, "good.toml".as_ref()).unwrap();
    assert_eq!(s.objects.len(), 3, "a sphere and the rectangle's two triangles");
    for (key, expected) in [
        ("exposure = 65", "an exposure of 65 stops"),
        ("tonemap = \"aces\"", "unknown variant"),
        ("clamp = 0", "greater than 0"),
        ("exr_half = 1", "expected a boolean"),
    ] {
        let text = GOOD.replace("height = 48\n", &format!("height = 48\n{key}\n"));
        let e = error_of(&text);
        assert_eq!(e.line, 5, "{key}: {e}");
        assert!(e.message.contains(expected), "{key}: {e}");
    }
    let text = GOOD
        .replace("height = 48\n", "height = 48\nexposure = -2.5\ntonemap = \"filmic\"\nexr_half = true\nclamp = 10\n");
    let s = parse_scene(&text, "good.toml".as_ref()).unwrap();
    assert_eq!(s.image.clamp, Some(10.0));
    assert_eq!(
        s.image.output,
        englobe_scene::OutputSettings { exposure: -2.5, tonemap: englobe_scene::ToneMap::Filmic, exr_half: true }
    );
}
