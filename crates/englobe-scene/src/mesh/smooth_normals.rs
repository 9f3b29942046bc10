//! Smooth vertex normals for meshes whose file has none, within a crease angle: at each vertex,
//! the normal of a triangle's corner is the mean of the normals of the triangles around the
//! vertex that meet this one's at most at the angle, each weighted by its angle at the vertex
//! (Thürmer and Wüthrich 1998, "Computing vertex normals from polygonal facets", which makes the
//! normal independent of how the surface is cut into triangles). Corners whose normals differ
//! get vertices of their own, so a crease stays sharp: a cube keeps its six face normals at any
//! angle below 90 degrees. Vertices are joined by position, not index, so that seams where a file
//! splits vertices for its texture coordinates are smoothed across too.

use std::collections::HashMap;

use englobe::Vec3;

/// Above this many triangles around one vertex the corners there keep their face normals, so
/// that a pathological fan (a cone of millions of triangles) costs linear time, not quadratic.
const MAX_VALENCE: usize = 4096;

/// The smoothed mesh: for each new vertex, the old vertex it copies and its normal; and the
/// triangles over the new vertices.
pub(super) struct Smoothed {
    pub source: Vec<u32>,
    pub normals: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

/// Smooth normals for `triangles` over `positions`, joining faces that meet at most at
/// `angle_degrees` (in `(0, 180]`).
pub(super) fn smooth_normals(positions: &[Vec3], triangles: &[[u32; 3]], angle_degrees: f32) -> Smoothed {
    let cos_limit = angle_degrees.to_radians().cos() - 1e-6;
    let face_normals: Vec<Vec3> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            (b - a).cross(c - a).normalize_or_zero()
        })
        .collect();
    let corner_angle = |t: &[u32; 3], k: usize| -> f32 {
        let p = positions[t[k] as usize];
        let (e1, e2) = (positions[t[(k + 1) % 3] as usize] - p, positions[t[(k + 2) % 3] as usize] - p);
        let a = e1.angle_between(e2);
        if a.is_finite() { a } else { 0.0 }
    };

    // Vertices by position (`+ 0.0` makes -0 and +0 one key).
    let mut ids: HashMap<[u32; 3], u32> = HashMap::new();
    let welded: Vec<u32> = positions
        .iter()
        .map(|p| {
            let key = (*p + Vec3::ZERO).to_array().map(f32::to_bits);
            let next = ids.len() as u32;
            *ids.entry(key).or_insert(next)
        })
        .collect();
    // The corners around each welded vertex, in triangle order (compressed rows).
    let mut start = vec![0usize; ids.len() + 1];
    for t in triangles {
        for &v in t {
            start[welded[v as usize] as usize + 1] += 1;
        }
    }
    for i in 0..ids.len() {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut around = vec![(0u32, 0u8); start[ids.len()]];
    for (f, t) in triangles.iter().enumerate() {
        for (k, &v) in t.iter().enumerate() {
            let w = welded[v as usize] as usize;
            around[fill[w]] = (f as u32, k as u8);
            fill[w] += 1;
        }
    }

    let mut out = Smoothed { source: Vec::new(), normals: Vec::new(), triangles: Vec::with_capacity(triangles.len()) };
    let mut vertex_of: HashMap<(u32, [u32; 3]), u32> = HashMap::new();
    for (f, t) in triangles.iter().enumerate() {
        let nf = face_normals[f];
        let mut tri = [0u32; 3];
        for k in 0..3 {
            let w = welded[t[k] as usize] as usize;
            let ring = &around[start[w]..start[w + 1]];
            let mut n = Vec3::ZERO;
            if ring.len() <= MAX_VALENCE {
                for &(g, kg) in ring {
                    let ng = face_normals[g as usize];
                    if g as usize == f || nf.dot(ng) >= cos_limit {
                        n += ng * corner_angle(&triangles[g as usize], kg as usize);
                    }
                }
            }
            let n = n.try_normalize().unwrap_or(nf);
            let key = (t[k], n.to_array().map(f32::to_bits));
            tri[k] = *vertex_of.entry(key).or_insert_with(|| {
                out.source.push(t[k]);
                out.normals.push(n);
                (out.source.len() - 1) as u32
            });
        }
        out.triangles.push(tri);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube of 12 triangles over 8 shared vertices.
    fn cube() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let p = (0..8).map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32)).collect();
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let t = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
        (p, t)
    }

    #[test]
    fn a_cube_keeps_its_six_face_normals() {
        let (p, t) = cube();
        for angle in [30.0, 60.0, 89.0] {
            let s = smooth_normals(&p, &t, angle);
            assert_eq!(s.normals.len(), 24, "each corner of the cube splits into three");
            for (f, tri) in s.triangles.iter().enumerate() {
                let face = (p[t[f][1] as usize] - p[t[f][0] as usize])
                    .cross(p[t[f][2] as usize] - p[t[f][0] as usize])
                    .normalize();
                for &v in tri {
                    assert!((s.normals[v as usize] - face).length() < 1e-6, "angle {angle}");
                    assert!(s.source[v as usize] < 8);
                }
            }
        }
        // Past 90 degrees the corners are rounded: (1, 1, 1) directions.
        let s = smooth_normals(&p, &t, 100.0);
        assert_eq!(s.normals.len(), 8);
        assert!((s.normals[s.triangles[0][0] as usize] - Vec3::splat(-1.0).normalize()).length() < 1e-6);
    }

    #[test]
    fn a_fine_sphere_gets_its_true_normals() {
        // A UV sphere of 64 x 32 quads, split at the seam (duplicated positions) as files do.
        let (n, m) = (64u32, 32u32);
        let mut p = Vec::new();
        for j in 0..=m {
            for i in 0..=n {
                let (theta, phi) =
                    (std::f32::consts::PI * j as f32 / m as f32, std::f32::consts::TAU * (i % n) as f32 / n as f32);
                p.push(Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin()));
            }
        }
        let at = |i: u32, j: u32| j * (n + 1) + i;
        let mut t = Vec::new();
        for j in 0..m {
            for i in 0..n {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                if j != 0 {
                    t.push([a, b, c]);
                }
                if j != m - 1 {
                    t.push([a, c, d]);
                }
            }
        }
        let s = smooth_normals(&p, &t, 60.0);
        // The normals follow the winding: all outward or all inward.
        let sign = s.normals[0].dot(p[s.source[0] as usize]).signum();
        // Worst error on the rings next to the poles (fans of thin triangles) and elsewhere.
        let (mut near_poles, mut elsewhere) = (0.0f32, 0.0f32);
        for (v, &src) in s.source.iter().enumerate() {
            let truth = p[src as usize].normalize() * sign;
            let error = s.normals[v].angle_between(truth).to_degrees();
            let ring = src / (n + 1);
            if ring <= 1 || ring >= m - 1 {
                near_poles = near_poles.max(error);
            } else {
                elsewhere = elsewhere.max(error);
            }
        }
        assert!(elsewhere < 0.5, "worst normal is {elsewhere} degrees off");
        // A ring of the 32 is 5.6 degrees: the pole's fan tilts its neighbours by at most half.
        assert!(near_poles < 3.0, "worst normal near the poles is {near_poles} degrees off");
        // The seam is smoothed across: one normal per position along it.
        let seam: Vec<_> =
            (0..s.source.len()).filter(|&v| s.source[v] % (n + 1) == 0 || s.source[v] % (n + 1) == n).collect();
        for &a in &seam {
            for &b in &seam {
                if p[s.source[a] as usize] == p[s.source[b] as usize] {
                    assert!((s.normals[a] - s.normals[b]).length() < 1e-6);
                }
            }
        }
    }
}
