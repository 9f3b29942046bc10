//! A robot's lidar: a fan of rays from a pose that moves through a room, against the room's
//! static walls and furniture (one `World`) and a door that swings as the robot goes (a
//! `TriangleBvh` refitted at every step instead of rebuilt). Each scan is one batch; the robot
//! prints, per pose, the nearest obstacle and how much of the fan came back.
//!
//! `cargo run --release --example lidar_scan [RAYS] [POSES]` (defaults 1080 and 10).

use englobe::{AaBox, AccelKind, Object, Ray, Sphere, TriangleBvh, Vec3, World};

/// How far the lidar sees.
const RANGE: f32 = 30.0;

/// The door: a panel 1 wide and 2 high hinged at (4, 0, -2), turned by `angle` about y.
fn door(angle: f32) -> Vec<[f32; 3]> {
    let (s, c) = angle.sin_cos();
    let hinge = Vec3::new(4.0, 0.0, -2.0);
    [(0.0, 0.0), (1.0, 0.0), (1.0, 2.0), (0.0, 2.0)]
        .map(|(w, h)| (hinge + Vec3::new(c * w, h, s * w)).to_array())
        .to_vec()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1).map(|a| a.parse::<usize>());
    let rays_per_scan = args.next().transpose()?.unwrap_or(1080).max(2);
    let poses = args.next().transpose()?.unwrap_or(10).max(1);

    let room: Vec<Object> = vec![
        AaBox::new(Vec3::new(-8.0, 0.0, -6.0), Vec3::new(8.0, 3.0, -5.8)).into(),
        AaBox::new(Vec3::new(-8.0, 0.0, 5.8), Vec3::new(8.0, 3.0, 6.0)).into(),
        AaBox::new(Vec3::new(-8.0, 0.0, -6.0), Vec3::new(-7.8, 3.0, 6.0)).into(),
        AaBox::new(Vec3::new(7.8, 0.0, -6.0), Vec3::new(8.0, 3.0, 6.0)).into(),
        AaBox::new(Vec3::new(-2.0, 0.0, 1.0), Vec3::new(0.5, 0.8, 2.5)).into(), // a table
        Sphere::new(Vec3::new(3.0, 0.4, 3.0), 0.4).into(),                      // a bin
    ];
    let world = World::build(room, AccelKind::BvhWide)?;
    let quad = [[0, 1, 2], [0, 2, 3]];
    let mut door_bvh = TriangleBvh::from_arrays(&door(0.0), &quad)?;

    let (mut rays, mut room_hits, mut door_hits) =
        (Vec::with_capacity(rays_per_scan), vec![None; rays_per_scan], vec![None; rays_per_scan]);
    println!("lidar: {rays_per_scan} rays over 270 degrees, range {RANGE}, {poses} poses");
    for step in 0..poses {
        let f = step as f32 / poses as f32;
        // The robot drives along an arc, facing along it; the door swings open as it goes.
        let theta = f * 2.5;
        let pose = Vec3::new(-5.0 + 8.0 * f, 0.5, -3.0 + 2.0 * theta.sin());
        let heading = theta.cos().atan2(1.0);
        let report = door_bvh.refit_arrays(&door(f * 1.4), &quad)?;
        rays.clear();
        rays.extend((0..rays_per_scan).map(|k| {
            let a = heading - 0.75 * std::f32::consts::PI
                + 1.5 * std::f32::consts::PI * k as f32 / (rays_per_scan - 1) as f32;
            Ray::segment(pose, Vec3::new(a.cos(), 0.0, a.sin()), 0.0, RANGE)
        }));
        world.closest_hits(&rays, &mut room_hits)?;
        door_bvh.closest_hits(&rays, &mut door_hits)?;
        let ranges: Vec<Option<(f32, bool)>> = room_hits
            .iter()
            .zip(&door_hits)
            .map(|(r, d)| match (r.map(|h| h.t), d.map(|h| h.t)) {
                (Some(r), Some(d)) if d < r => Some((d, true)),
                (Some(r), _) => Some((r, false)),
                (None, Some(d)) => Some((d, true)),
                (None, None) => None,
            })
            .collect();
        let returned = ranges.iter().flatten().count();
        let on_door = ranges.iter().flatten().filter(|(_, door)| *door).count();
        let (nearest, k) = ranges
            .iter()
            .enumerate()
            .filter_map(|(k, r)| r.map(|(t, _)| (t, k)))
            .fold((f32::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a });
        let bearing = (k as f32 / (rays_per_scan - 1) as f32 * 270.0) - 135.0;
        println!(
            "  pose {step:2} at ({:5.2}, {:5.2}) heading {:6.1} deg: {returned:4} returns ({on_door} on the door), \
             nearest {nearest:5.2} at {bearing:6.1} deg; door {}",
            pose.x,
            pose.z,
            heading.to_degrees(),
            if report.rebuilt { "rebuilt" } else { "refitted" },
        );
    }
    Ok(())
}
