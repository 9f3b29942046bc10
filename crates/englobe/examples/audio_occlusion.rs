//! Audio occlusion: how much of each sound source a listener hears through the walls of a small
//! building. The direct path from the listener to each source is one segment; a filter that
//! counts every surface the segment crosses and rejects them all (so the query goes on to the
//! end) gives the walls in the way, and each wall costs a fixed transmission loss on top of the
//! distance's.
//!
//! `cargo run --release --example audio_occlusion [SOURCES]` (default 8).

use englobe::{AaBox, AccelKind, NoCount, Object, Ray, Sphere, TriangleMesh, Vec3, World, WorldHit};

/// Loss of one wall crossed, in decibels (a plasterboard partition, about).
const WALL_LOSS_DB: f32 = 12.0;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let sources = std::env::args().nth(1).map(|a| a.parse::<usize>()).transpose()?.unwrap_or(8).max(1);

    // Four rooms of 10 x 10 units, walls 0.2 thick and 3 high, one doorway per inner wall, and a
    // pillar (a mesh) in the first room.
    let wall = |a: [f32; 3], b: [f32; 3]| -> Object { AaBox::new(Vec3::from(a), Vec3::from(b)).into() };
    let mut objects: Vec<Object> = vec![
        wall([-10.0, 0.0, -10.1], [10.0, 3.0, -9.9]),
        wall([-10.0, 0.0, 9.9], [10.0, 3.0, 10.1]),
        wall([-10.1, 0.0, -10.0], [-9.9, 3.0, 10.0]),
        wall([9.9, 0.0, -10.0], [10.1, 3.0, 10.0]),
        // The inner walls, each with a doorway 1.5 wide.
        wall([-0.1, 0.0, -10.0], [0.1, 3.0, -6.0]),
        wall([-0.1, 0.0, -4.5], [0.1, 3.0, 10.0]),
        wall([-10.0, 0.0, -0.1], [4.0, 3.0, 0.1]),
        wall([5.5, 0.0, -0.1], [10.0, 3.0, 0.1]),
    ];
    let (c, r) = (Vec3::new(-5.0, 0.0, -5.0), 0.6);
    let ring: Vec<[f32; 3]> = (0..16)
        .flat_map(|k| {
            let (s, co) = (k as f32 / 16.0 * std::f32::consts::TAU).sin_cos();
            [[c.x + r * co, 0.0, c.z + r * s], [c.x + r * co, 3.0, c.z + r * s]]
        })
        .collect();
    let sides: Vec<[u32; 3]> = (0..16u32)
        .flat_map(|k| {
            let (a, b) = (2 * k, 2 * ((k + 1) % 16));
            [[a, b, a + 1], [b, b + 1, a + 1]]
        })
        .collect();
    objects.push(TriangleMesh::from_arrays(&ring, &sides)?.into());
    // A glass screen beside the listener: it blocks the line of sight, not the sound, so the
    // filter leaves it out (it is the last object).
    objects.push(Sphere::new(Vec3::new(-6.0, 1.5, -7.0), 0.3).into());
    let walls = objects.len() - 1;
    let world = World::build(objects, AccelKind::BvhWide)?;

    let listener = Vec3::new(-7.0, 1.6, -7.0);
    println!("a building of four rooms: {} objects, listener at {listener}", walls + 1);
    for k in 0..sources {
        let f = (k as f32 + 0.5) / sources as f32;
        let (s, co) = (f * std::f32::consts::TAU * 1.3).sin_cos();
        let source = Vec3::new(9.0 * co * f.sqrt() + 1.0, 1.2, 9.0 * s * f.sqrt());
        let path = Ray::segment(listener, source - listener, 0.0, 1.0);
        // Every object on the way, the screen excepted; all rejected, so the query visits them
        // all.
        let mut crossed = Vec::new();
        world.any_hit_filtered(&path, &mut NoCount, |h: &WorldHit| {
            if (h.object as usize) < walls && !crossed.contains(&h.object) {
                crossed.push(h.object);
            }
            false
        });
        let distance = (source - listener).length();
        let loss = 20.0 * distance.max(1.0).log10() + WALL_LOSS_DB * crossed.len() as f32;
        let direct = !world.any_hit(&path, &mut NoCount);
        println!(
            "  source {k:2} at ({:5.1}, {:4.1}, {:5.1}): {distance:5.1} away, {} in the way{}, heard at -{loss:4.1} dB",
            source.x,
            source.y,
            source.z,
            match crossed.len() {
                0 => "nothing".to_owned(),
                1 => "1 object".to_owned(),
                n => format!("{n} objects"),
            },
            if direct { " (in sight)" } else { "" },
        );
    }
    Ok(())
}
