//! Ray cones in renders: a checkerboard too far away to resolve renders as its grey mean with
//! cones and as aliased black and white without; a magnified texture and every untextured scene
//! render the same bytes with and without cones; the path tracer filters its first hits too; a
//! board mapped by a second texture coordinate set is filtered by that set's footprint.

use std::sync::Arc;

use englobe::{AccelKind, Object, TriangleMesh, Vec2, Vec3};
use englobe_render::{Renderer, build_world};
use englobe_scene::texture::{Sampler, TexelImage, Texture, TextureSource};
use englobe_scene::{
    IntegratorKind, Material, MaterialTextures, Scene, SceneObject, TextureFilter, TextureRef, load_scene, parse_scene,
};

/// A 32 x 32 square facing a camera 8 pixels high at distance `distance`, lit by a white ambient
/// term alone, textured by a `texels` x `texels` checkerboard of single black and white texels
/// (linear 0 and 1: the mean is one half).
fn checkerboard(distance: f32, texels: u32) -> Scene {
    let text = format!(
        "[image]\nwidth = 8\nheight = 8\nambient = [1, 1, 1]\nmax_depth = 0\n\
         [camera]\nposition = [0, 0, {distance}]\nlook_at = [0, 0, 0]\nfov = 20\n"
    );
    let mut scene = parse_scene(&text, "checker.toml".as_ref()).unwrap();
    let t = (0..texels * texels)
        .map(|i| if (i % texels + i / texels) % 2 == 0 { [255; 4] } else { [0, 0, 0, 255] })
        .collect();
    let image = Arc::new(TexelImage::from_rgba8(texels, texels, t).unwrap());
    scene.textures.push(Arc::new(Texture::new(
        "checker",
        TextureSource::Embedded("test".into()),
        Sampler::default(),
        image,
    )));
    scene.materials.push(Material {
        diffuse: Vec3::ONE,
        textures: MaterialTextures { base_color: Some(TextureRef::new(0)), ..Default::default() },
        ..Material::default()
    });
    let s = 16.0;
    let positions = vec![Vec3::new(-s, -s, 0.0), Vec3::new(s, -s, 0.0), Vec3::new(s, s, 0.0), Vec3::new(-s, s, 0.0)];
    let uvs = vec![Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.0)];
    let quad = TriangleMesh::new(positions, vec![[0, 1, 2], [0, 2, 3]]).unwrap().with_uvs(uvs).unwrap();
    let material = (scene.materials.len() - 1) as u32;
    scene.objects.push(SceneObject::new(Object::Mesh(Arc::new(quad)), material));
    scene
}

fn render(scene: &Scene, filter: TextureFilter) -> Vec<Vec3> {
    let mut scene = scene.clone();
    scene.image.texture_filter = filter;
    let world = build_world(&scene, AccelKind::BvhWide).unwrap();
    Renderer::new(&scene, &world).render().unwrap().film.pixels().to_vec()
}

fn bits(pixels: &[Vec3]) -> Vec<[u32; 3]> {
    pixels.iter().map(|p| p.to_array().map(f32::to_bits)).collect()
}

#[test]
fn a_far_checkerboard_renders_as_its_grey_mean() {
    // The image spans 2 tan(10°) d = 0.35 d units, so a pixel covers 0.044 d units, or 5.6 d
    // texels of a 4096-texel board over 32 units: from 56 texels at d = 10 to 450 at d = 80
    // (where the board still fills the image). Every level below the image is exactly grey.
    for distance in [10.0f32, 30.0, 80.0] {
        let scene = checkerboard(distance, 4096);
        let coned = render(&scene, TextureFilter::Cone);
        let worst = coned.iter().map(|p| (p.x - 0.5).abs().max((p.y - 0.5).abs())).fold(0.0f32, f32::max);
        assert!(worst < 1e-3, "at {distance}: a pixel {worst} from the mean");
        // Without cones each pixel reads one point of the board: black, white or between.
        let point = render(&scene, TextureFilter::None);
        let spread = point.iter().map(|p| (p.x - 0.5).abs()).fold(0.0f32, f32::max);
        assert!(spread > 0.2, "at {distance}: point samples alias ({spread})");
    }
}

#[test]
fn a_board_read_in_the_second_set_is_filtered_by_that_set_footprint() {
    // Set 1 spreads the far board over the square as before; set 0 squeezes it into the first
    // white texel (a footprint far under a texel). The base colour reads set 1: the grey mean
    // with cones, aliasing without. Set 0's coordinates would render white, and set 0's
    // footprint with set 1's coordinates would alias.
    let mut scene = checkerboard(80.0, 4096);
    let object = scene.objects.last_mut().unwrap();
    let Object::Mesh(quad) = &object.object else { unreachable!("the board is a mesh") };
    let set1 = quad.uvs().unwrap().to_vec();
    let set0 = set1.iter().map(|uv| *uv / 8192.0).collect();
    let two = TriangleMesh::new(quad.positions().to_vec(), quad.triangles().to_vec())
        .and_then(|m| m.with_uvs(set0))
        .and_then(|m| m.with_uvs1(set1))
        .unwrap();
    object.object = Object::Mesh(Arc::new(two));
    let material = scene.materials.last_mut().unwrap();
    material.textures.base_color = Some(TextureRef { uv_set: 1, ..TextureRef::new(0) });
    let coned = render(&scene, TextureFilter::Cone);
    let worst = coned.iter().map(|p| (p.x - 0.5).abs().max((p.y - 0.5).abs())).fold(0.0f32, f32::max);
    assert!(worst < 1e-3, "a pixel {worst} from the mean");
    let point = render(&scene, TextureFilter::None);
    let spread = point.iter().map(|p| (p.x - 0.5).abs()).fold(0.0f32, f32::max);
    assert!(spread > 0.2, "point samples of set 1 alias ({spread})");
}

#[test]
fn magnified_textures_and_untextured_scenes_keep_their_bytes() {
    // A 4 x 4 board seen from close by: a texel spans many pixels, the footprint is under a
    // texel everywhere, and the cone changes nothing.
    let near = checkerboard(10.0, 4);
    assert_eq!(bits(&render(&near, TextureFilter::Cone)), bits(&render(&near, TextureFilter::None)));
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    for name in ["default.toml", "glass.toml", "mirrors.toml", "cornell-box-path.toml"] {
        let mut scene = load_scene(&root.join(name)).unwrap();
        assert!(scene.textures.is_empty(), "{name} has no textures");
        (scene.image.width, scene.image.height, scene.image.samples) = (24, 16, 2);
        let (a, b) = (render(&scene, TextureFilter::Cone), render(&scene, TextureFilter::None));
        assert_eq!(bits(&a), bits(&b), "{name}");
    }
}

#[test]
fn the_path_tracer_filters_its_first_hits() {
    let mut scene = checkerboard(80.0, 4096);
    scene.image.integrator = IntegratorKind::Path;
    scene.image.max_depth = 2;
    scene.image.background = Vec3::ONE;
    scene.image.samples = 4;
    // Ambient is not used by the path tracer: the white background lights the board, so a
    // pixel is the albedo its first hit reads (its bounce escapes to the white sky): about one
    // half everywhere with cones, black or white or between without.
    let contrast =
        |p: &[Vec3]| p.iter().map(|c| c.x).fold(0.0f32, f32::max) - p.iter().map(|c| c.x).fold(1.0, f32::min);
    let (coned, point) = (render(&scene, TextureFilter::Cone), render(&scene, TextureFilter::None));
    assert!(contrast(&coned) < 0.5 * contrast(&point), "{} against {}", contrast(&coned), contrast(&point));
}
