//! Materials in the integrators: a cut-out texel is passed through by closest-hit and shadow
//! queries alike, in every structure, and partly covered surfaces are passed through by both
//! kinds of query at the same points, reading the coverage in the base colour texture's
//! coordinate set; the back faces of single-sided materials are culled by both
//! queries; metallic-roughness surfaces vanish in a white furnace where their BSDF conserves
//! energy.

use std::sync::Arc;

use englobe::{AccelKind, NoCount, Object, Ray, TriangleMesh, Vec2, Vec3};
use englobe_render::visibility::Visibility;
use englobe_render::{Renderer, build_world};
use englobe_scene::texture::{Sampler, TexelImage, Texture, TextureSource};
use englobe_scene::{
    Alpha, AlphaMode, Material, MaterialModel, MaterialTextures, Scene, SceneObject, TextureRef, parse_scene,
};

const BEHIND: &str = "
[image]
width = 8
height = 8

[camera]
position = [0, 0, 5]
look_at = [0, 0, 0]

[[sphere]]
center = [0, 0, -3]
radius = 2
";

/// A unit quad in the plane z = 0 whose material's coverage is `alpha` at each of its two texels
/// (left half, right half), with `mode`, in front of a sphere.
fn quad_scene(alpha: [u8; 2], mode: AlphaMode) -> Scene {
    let mut scene = parse_scene(BEHIND, "quad.toml".as_ref()).unwrap();
    let image =
        Arc::new(TexelImage::from_rgba8(2, 1, vec![[255, 255, 255, alpha[0]], [255, 255, 255, alpha[1]]]).unwrap());
    scene.textures.push(Arc::new(Texture::new(
        "coverage",
        TextureSource::Embedded("test".into()),
        Sampler::default(),
        image,
    )));
    scene.materials.push(Material {
        alpha: Alpha { mode, factor: 1.0 },
        textures: MaterialTextures { base_color: Some(TextureRef::new(0)), ..Default::default() },
        ..Material::default()
    });
    let positions = vec![
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
    ];
    let uvs = vec![Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.0)];
    let quad = TriangleMesh::new(positions, vec![[0, 1, 2], [0, 2, 3]]).unwrap().with_uvs(uvs).unwrap();
    let material = (scene.materials.len() - 1) as u32;
    scene.objects.push(SceneObject::new(Object::Mesh(Arc::new(quad)), material));
    scene
}

#[test]
fn a_cut_out_texel_is_passed_through_by_both_queries_in_every_structure() {
    let scene = quad_scene([0, 255], AlphaMode::Mask { cutoff: 0.5 });
    let quad = scene.objects.len() as u32 - 1;
    for &kind in AccelKind::ALL {
        let world = build_world(&scene, kind).unwrap();
        let vis = Visibility::new(&scene, &world);
        for y in [-0.6f32, 0.0, 0.7] {
            // Left half: cut out, the ray goes on to the sphere; a shadow ray ending before the
            // sphere sees nothing.
            let left = Ray::new(Vec3::new(-0.5, y, 5.0), -Vec3::Z);
            let hit = vis.closest_hit(&left, &mut NoCount).expect("the sphere behind");
            assert!(hit.object == 0 && hit.t > 5.5, "{kind}: the left half is cut out, {hit:?}");
            assert!(world.closest_hit(&left, &mut NoCount).is_some_and(|h| h.object == quad), "{kind}: unfiltered");
            assert!(!vis.any_hit(&Ray::segment(left.origin(), -Vec3::Z, 0.0, 5.5), &mut NoCount), "{kind}");
            // Right half: solid.
            let right = Ray::new(Vec3::new(0.5, y, 5.0), -Vec3::Z);
            let hit = vis.closest_hit(&right, &mut NoCount).expect("the quad");
            assert_eq!((hit.object, hit.t), (quad, 5.0), "{kind}: the right half is there");
            assert!(vis.any_hit(&Ray::segment(right.origin(), -Vec3::Z, 0.0, 5.5), &mut NoCount), "{kind}");
        }
    }
}

#[test]
fn the_coverage_is_read_in_the_base_colour_texture_set() {
    // Set 0 maps the whole quad into the cut-out left texel, set 1 into the solid right one.
    for (set, solid) in [(0, false), (1, true)] {
        let mut scene = quad_scene([0, 255], AlphaMode::Mask { cutoff: 0.5 });
        let object = scene.objects.last_mut().unwrap();
        let Object::Mesh(quad) = &object.object else { unreachable!("the quad is a mesh") };
        let uvs = quad.uvs().unwrap();
        let left = uvs.iter().map(|uv| Vec2::new(0.05 + 0.4 * uv.x, uv.y)).collect();
        let right = uvs.iter().map(|uv| Vec2::new(0.55 + 0.4 * uv.x, uv.y)).collect();
        let two = TriangleMesh::new(quad.positions().to_vec(), quad.triangles().to_vec())
            .and_then(|m| m.with_uvs(left))
            .and_then(|m| m.with_uvs1(right))
            .unwrap();
        object.object = Object::Mesh(Arc::new(two));
        scene.materials.last_mut().unwrap().textures.base_color =
            Some(TextureRef { uv_set: set, ..TextureRef::new(0) });
        let quad = scene.objects.len() as u32 - 1;
        let world = build_world(&scene, AccelKind::BvhWide).unwrap();
        let vis = Visibility::new(&scene, &world);
        for x in [-0.6f32, 0.0, 0.7] {
            let ray = Ray::new(Vec3::new(x, 0.3, 5.0), -Vec3::Z);
            let hit = vis.closest_hit(&ray, &mut NoCount).expect("the quad or the sphere");
            assert_eq!(hit.object == quad, solid, "set {set}, x {x}: {hit:?}");
            assert_eq!(vis.any_hit(&Ray::segment(ray.origin(), -Vec3::Z, 0.0, 5.5), &mut NoCount), solid, "set {set}");
        }
    }
}

#[test]
fn partly_covered_surfaces_are_passed_where_both_queries_agree() {
    let scene = quad_scene([128, 128], AlphaMode::Blend);
    let quad = scene.objects.len() as u32 - 1;
    let world = build_world(&scene, AccelKind::BvhWide).unwrap();
    let vis = Visibility::new(&scene, &world);
    let (mut passed, n) = (0, 40);
    for i in 0..n {
        for j in 0..n {
            let o = Vec3::new(-0.95 + 1.9 * i as f32 / n as f32, -0.95 + 1.9 * j as f32 / n as f32, 5.0);
            let through = vis.closest_hit(&Ray::new(o, -Vec3::Z), &mut NoCount).expect("quad or sphere").object != quad;
            let blocked = vis.any_hit(&Ray::segment(o, -Vec3::Z, 0.0, 5.5), &mut NoCount);
            assert_eq!(through, !blocked, "ray {i},{j}: the two queries decide alike");
            passed += through as u32;
        }
    }
    // Coverage 128/255: about half the rays pass (1600 rays, a binomial's sd is 20).
    let share = passed as f64 / (n * n) as f64;
    assert!((share - (1.0 - 128.0 / 255.0)).abs() < 0.05, "{share}");
}

#[test]
fn single_sided_triangles_are_culled_from_behind_by_both_queries_in_every_structure() {
    // The quad's winding faces +z, toward the camera at z = 5. A second quad at z = -6, facing
    // +z too, stands behind the sphere.
    let with = |double_sided: bool, transmission: f32| {
        let mut scene = quad_scene([255, 255], AlphaMode::Opaque);
        let m = scene.materials.last_mut().unwrap();
        m.double_sided = double_sided;
        m.model = MaterialModel::MetallicRoughness { metallic: 0.0, roughness: 0.5, transmission };
        scene
    };
    let front = Ray::new(Vec3::new(0.2, 0.1, 5.0), -Vec3::Z);
    let back = Ray::new(Vec3::new(0.2, 0.1, -0.5), Vec3::Z);
    for &kind in AccelKind::ALL {
        for (double_sided, transmission, culled) in [(false, 0.0, true), (true, 0.0, false), (false, 1.0, false)] {
            let scene = with(double_sided, transmission);
            let quad = scene.objects.len() as u32 - 1;
            let world = build_world(&scene, kind).unwrap();
            let vis = Visibility::new(&scene, &world);
            let what = format!("{kind}, double_sided {double_sided}, transmission {transmission}");
            let hit = vis.closest_hit(&front, &mut NoCount).expect("the quad's front");
            assert_eq!((hit.object, hit.t), (quad, 5.0), "{what}: the front face is always there");
            assert!(vis.any_hit(&Ray::segment(front.origin(), front.dir(), 0.0, 5.5), &mut NoCount), "{what}");
            let hit = vis.closest_hit(&back, &mut NoCount);
            assert_eq!(hit.is_none(), culled, "{what}: from behind, {hit:?}");
            assert_eq!(!vis.any_hit(&back, &mut NoCount), culled, "{what}: a shadow ray from behind");
            assert!(world.closest_hit(&back, &mut NoCount).is_some(), "{what}: the unfiltered query sees it");
        }
    }
}

/// The mean of the film's pixels of a furnace: one sphere of `material` under a white sky.
fn furnace(material: &str) -> f32 {
    let text = format!(
        "[image]\nwidth = 8\nheight = 8\nsamples = 256\nmax_depth = 16\nintegrator = \"path\"\n\n\
         [camera]\nposition = [0, 0, 4]\nlook_at = [0, 0, 0]\nfov = 20\n\n[environment]\ncolor = [1, 1, 1]\n\n\
         [materials.m]\n{material}\n\n[[sphere]]\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n"
    );
    let scene = parse_scene(&text, "furnace.toml".as_ref()).unwrap();
    let world = build_world(&scene, AccelKind::BvhWide).unwrap();
    let out = Renderer::new(&scene, &world).render().unwrap();
    let f = &out.film;
    let mut sum = 0.0;
    for y in 0..f.height() {
        for x in 0..f.width() {
            sum += f.get(x, y).element_sum() / 3.0;
        }
    }
    sum / (f.width() * f.height()) as f32
}

#[test]
fn metallic_roughness_surfaces_vanish_in_a_white_furnace() {
    // The glTF dielectric base conserves energy (its diffuse part is coupled by albedo scaling,
    // see crates/englobe-render/src/bsdf), a white mirror reflects everything, and smooth glass
    // reflects or transmits everything: each is seen as the white sky around it.
    for material in [
        "model = \"metallic_roughness\"\nbase_color = [1, 1, 1]\nmetallic = 0\nroughness = 0.5",
        "model = \"metallic_roughness\"\nbase_color = [1, 1, 1]\nmetallic = 0\nroughness = 0.1",
        "model = \"metallic_roughness\"\nbase_color = [1, 1, 1]\nmetallic = 1\nroughness = 0",
        "model = \"metallic_roughness\"\nbase_color = [1, 1, 1]\ntransmission = 1\nroughness = 0",
    ] {
        let mean = furnace(material);
        assert!((mean - 1.0).abs() < 0.02, "{material}: {mean}");
    }
    // A grey one is not white: the test can tell.
    let grey = furnace("model = \"metallic_roughness\"\nbase_color = [0.5, 0.5, 0.5]\nroughness = 0.5");
    assert!(grey < 0.8, "{grey}");
}
