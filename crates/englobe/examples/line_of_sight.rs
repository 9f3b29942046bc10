//! Line of sight on a generated terrain: which observers, standing on rolling hills, can see one
//! another. The terrain is a height field turned into triangles from plain arrays; each pair of
//! observers is one segment, all of them traced in one batch of any-hit queries.
//!
//! `cargo run --release --example line_of_sight [GRID] [OBSERVERS]` (defaults 256 and 12).

use englobe::{NoCount, Ray, TriangleBvh, Vec3};

/// Rolling hills: a few sines, about 40 units high over a 1000-unit square.
fn height(x: f32, z: f32) -> f32 {
    18.0 * (x * 0.011).sin() * (z * 0.007).cos() + 12.0 * (x * 0.023 + z * 0.019).sin() + 6.0 * (z * 0.041).sin()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1).map(|a| a.parse::<usize>());
    let grid = args.next().transpose()?.unwrap_or(256).max(2);
    let observers = args.next().transpose()?.unwrap_or(12).max(2);
    let size = 1000.0;
    let cell = size / (grid - 1) as f32;

    // The height field as vertices and two triangles per cell.
    let mut vertices = Vec::with_capacity(grid * grid);
    for j in 0..grid {
        for i in 0..grid {
            let (x, z) = (i as f32 * cell, j as f32 * cell);
            vertices.push([x, height(x, z), z]);
        }
    }
    let mut triangles = Vec::with_capacity(2 * (grid - 1) * (grid - 1));
    for j in 0..grid as u32 - 1 {
        for i in 0..grid as u32 - 1 {
            let v = j * grid as u32 + i;
            triangles.push([v, v + grid as u32, v + 1]);
            triangles.push([v + 1, v + grid as u32, v + grid as u32 + 1]);
        }
    }
    let terrain = TriangleBvh::from_arrays(&vertices, &triangles)?;

    // Observers on a spiral over the square, eyes 2 units above the ground (found by a ray down).
    let eyes: Vec<Vec3> = (0..observers)
        .map(|k| {
            let f = (k as f32 + 0.5) / observers as f32;
            let (s, c) = (f * 17.0).sin_cos();
            let (x, z) = (size * (0.5 + 0.42 * f.sqrt() * c), size * (0.5 + 0.42 * f.sqrt() * s));
            let down = Ray::new(Vec3::new(x, 1000.0, z), -Vec3::Y);
            let ground = terrain.closest_hit(&down, &mut NoCount).map_or(0.0, |h| down.at(h.t).y);
            Vec3::new(x, ground + 2.0, z)
        })
        .collect();

    // One segment per pair, from one pair of eyes to the other (t from 0 to 1), in one batch.
    let pairs: Vec<(usize, usize)> = (0..observers).flat_map(|a| (a + 1..observers).map(move |b| (a, b))).collect();
    let rays: Vec<Ray> = pairs.iter().map(|&(a, b)| Ray::segment(eyes[a], eyes[b] - eyes[a], 0.0, 1.0)).collect();
    let mut blocked = vec![false; rays.len()];
    terrain.any_hits(&rays, &mut blocked)?;

    let mut sees = vec![vec![false; observers]; observers];
    for (&(a, b), &hidden) in pairs.iter().zip(&blocked) {
        sees[a][b] = !hidden;
        sees[b][a] = !hidden;
    }
    println!("terrain: {grid} x {grid} vertices, {} triangles", triangles.len());
    println!(
        "{observers} observers, {} pairs: {} in sight of each other",
        pairs.len(),
        blocked.iter().filter(|b| !**b).count()
    );
    for (a, row) in sees.iter().enumerate() {
        let line: String = row
            .iter()
            .enumerate()
            .map(|(b, &s)| {
                if a == b {
                    '\\'
                } else if s {
                    '#'
                } else {
                    '.'
                }
            })
            .collect();
        let p = eyes[a];
        println!("  observer {a:2} at ({:6.1}, {:5.1}, {:6.1}) sees {line}", p.x, p.y, p.z);
    }
    Ok(())
}
