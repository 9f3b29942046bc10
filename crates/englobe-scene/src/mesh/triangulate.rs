//! Polygons to triangles. Convex polygons become a fan from their first vertex (what every
//! loader does, and exact for them); concave ones, which a fan would cover wrongly, are cut by
//! ear clipping (Meisters 1975, "Polygons Have Ears") in the plane of their Newell normal
//! (Newell's method, as in Sutherland, Sproull and Schumacker 1974, "A Characterization of Ten
//! Hidden-Surface Algorithms").

use englobe::Vec3;
use glam::{DVec2, DVec3};

/// Polygons with more vertices than this are fanned without the concavity test: the ear search
/// costs up to the cube of the vertex count, and a hostile file could hold many huge polygons.
pub(super) const MAX_EAR_CLIPPED: usize = 64;

/// Appends the triangles of the polygon `poly` (vertex indices into `positions`, in order) to
/// `out`, keeping its winding. Returns true if the polygon was concave and ear-clipped.
pub(super) fn triangulate(positions: &[Vec3], poly: &[u32], out: &mut Vec<[u32; 3]>) -> bool {
    if poly.len() < 3 {
        return false;
    }
    let fan = |out: &mut Vec<[u32; 3]>| {
        for k in 1..poly.len() - 1 {
            out.push([poly[0], poly[k], poly[k + 1]]);
        }
    };
    if poly.len() == 3 || poly.len() > MAX_EAR_CLIPPED {
        fan(out);
        return false;
    }
    let p3: Vec<DVec3> = poly.iter().map(|&i| positions[i as usize].as_dvec3()).collect();
    let mut normal = DVec3::ZERO;
    for (k, a) in p3.iter().enumerate() {
        let b = p3[(k + 1) % p3.len()];
        normal += DVec3::new((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
    }
    // Drop the normal's largest axis; flip one axis if needed so that the polygon turns
    // counter-clockwise in 2D.
    let axis = normal.abs().max_position();
    let sign = if normal[axis] < 0.0 { -1.0 } else { 1.0 };
    let p: Vec<DVec2> = p3
        .iter()
        .map(|q| match axis {
            0 => DVec2::new(q.y, q.z * sign),
            1 => DVec2::new(q.z, q.x * sign),
            _ => DVec2::new(q.x, q.y * sign),
        })
        .collect();
    let turn = |a: DVec2, b: DVec2, c: DVec2| (b - a).perp_dot(c - b);
    let n = p.len();
    if normal == DVec3::ZERO || (0..n).all(|k| turn(p[k], p[(k + 1) % n], p[(k + 2) % n]) >= 0.0) {
        fan(out);
        return false;
    }

    let mut remaining: Vec<usize> = (0..n).collect();
    while remaining.len() > 3 {
        let m = remaining.len();
        let ear = (0..m).find(|&k| {
            let (a, b, c) = (remaining[(k + m - 1) % m], remaining[k], remaining[(k + 1) % m]);
            turn(p[a], p[b], p[c]) > 0.0
                && remaining.iter().all(|&o| o == a || o == b || o == c || !inside(p[o], p[a], p[b], p[c]))
        });
        let Some(k) = ear else { break }; // self-intersecting: fan what is left
        let (a, b, c) = (remaining[(k + m - 1) % m], remaining[k], remaining[(k + 1) % m]);
        out.push([poly[a], poly[b], poly[c]]);
        remaining.remove(k);
    }
    for k in 1..remaining.len() - 1 {
        out.push([poly[remaining[0]], poly[remaining[k]], poly[remaining[k + 1]]]);
    }
    true
}

/// True if `q` lies in the counter-clockwise triangle `a b c` or on its border.
fn inside(q: DVec2, a: DVec2, b: DVec2, c: DVec2) -> bool {
    (b - a).perp_dot(q - a) >= 0.0 && (c - b).perp_dot(q - b) >= 0.0 && (a - c).perp_dot(q - c) >= 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(positions: &[Vec3], tris: &[[u32; 3]]) -> f32 {
        tris.iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| positions[i as usize]);
                (b - a).cross(c - a).z * 0.5
            })
            .sum()
    }

    #[test]
    fn convex_polygons_are_fans() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let mut out = vec![];
        assert!(!triangulate(&p, &[0, 1, 2, 3], &mut out));
        assert_eq!(out, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn concave_polygons_keep_their_area_and_winding() {
        // An L shape whose fan from vertex 0 would cover the notch: area 3.
        let p = [
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(1.0, 2.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
        ];
        let poly = [0, 1, 2, 3, 4, 5];
        let mut fan = vec![];
        for k in 1..5 {
            fan.push([0, k, k + 1]);
        }
        let mut out = vec![];
        assert!(triangulate(&p, &poly, &mut out));
        assert_eq!(out.len(), 4);
        assert!((area(&p, &out) - 3.0).abs() < 1e-6, "{out:?}");
        assert!(out.iter().all(|t| area(&p, &[*t]) > 0.0), "every triangle keeps the winding: {out:?}");
        // Reversed, the polygon faces -z: still exact.
        let rev: Vec<u32> = poly.iter().rev().copied().collect();
        let mut out = vec![];
        triangulate(&p, &rev, &mut out);
        assert!((area(&p, &out) + 3.0).abs() < 1e-6);
    }
}
