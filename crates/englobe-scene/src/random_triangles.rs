//! `[[random_triangles]]` entries: a box filled uniformly with small random triangles, generated
//! from a seed. It is the "uniformly filled scene" on which uniform grids are at their best, and
//! what no mesh file gives: a scene whose density is the same everywhere.
//!
//! Triangle `i` has its centre uniform in `min..max` and its three vertices at that centre plus
//! offsets uniform in `[-size / 2, size / 2]` on each axis. The numbers come from PCG32 (O'Neill
//! 2014, "PCG: A Family of Simple Fast Space-Efficient Statistically Good Algorithms for Random
//! Number Generation"): `rand_pcg::Pcg32` started with `SeedableRng::seed_from_u64(seed)`, both
//! portable (the same numbers on every machine) and, by their crates' rules, changed only in a
//! breaking release. The floats are made here from the top 24 bits of each 32-bit output rather
//! than by `rand`'s distributions, which `rand` may change in its own breaking releases, so that a
//! seed keeps its triangles. A triangle whose corners come out on one line (area zero, a chance
//! of about one in 2^40) is drawn again.

use englobe::{Object, TriangleMesh, Vec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg32;
use toml::Spanned;

use crate::error::SceneError;
use crate::format::RandomTrianglesDef;
use crate::parse::Converter;

/// Most triangles one `[[random_triangles]]` entry may generate.
pub const MAX_RANDOM_TRIANGLES: u64 = 1 << 24;

/// Uniform in `[0, 1)`, from the top 24 bits of the next output (all an `f32` mantissa holds).
fn unit(rng: &mut Pcg32) -> f32 {
    (rng.next_u32() >> 8) as f32 / (1u32 << 24) as f32
}

fn in_box(rng: &mut Pcg32, min: Vec3, max: Vec3) -> Vec3 {
    let u = Vec3::new(unit(rng), unit(rng), unit(rng));
    min + (max - min) * u
}

/// `count` triangles of size `size` with centres in `min..max`, from `seed`.
pub fn random_triangles(count: u32, min: Vec3, max: Vec3, size: f32, seed: u64) -> Vec<[Vec3; 3]> {
    let mut rng = Pcg32::seed_from_u64(seed);
    let half = Vec3::splat(size * 0.5);
    (0..count)
        .map(|_| {
            loop {
                let c = in_box(&mut rng, min, max);
                let mut corner = || in_box(&mut rng, c - half, c + half);
                let v = [corner(), corner(), corner()];
                if (v[1] - v[0]).cross(v[2] - v[0]).length_squared() > 0.0 {
                    break v;
                }
            }
        })
        .collect()
}

impl Converter<'_> {
    /// The mesh of one `[[random_triangles]]` entry.
    pub(crate) fn random_triangles(&self, def: Spanned<RandomTrianglesDef>) -> Result<Object, SceneError> {
        let span = def.span();
        let d = def.into_inner();
        let count = *d.count.get_ref();
        if count == 0 || count as u64 > MAX_RANDOM_TRIANGLES {
            return Err(
                self.err(d.count.span(), format!("expected 1 to {MAX_RANDOM_TRIANGLES} triangles, found {count}"))
            );
        }
        let (min, max) = (d.min.0, d.max.0);
        if !min.cmple(max).all() {
            return Err(
                self.err(span, format!("random triangles need min <= max on every axis, found {min} and {max}"))
            );
        }
        let half = Vec3::splat(d.size.0 * 0.5);
        if !(max - min).is_finite() || !(min - half).is_finite() || !(max + half).is_finite() {
            return Err(self.err(span, "the random triangles reach beyond what 32-bit floats can hold"));
        }
        let triangles = random_triangles(count, min, max, d.size.0, d.seed);
        let positions: Vec<Vec3> = triangles.iter().flatten().copied().collect();
        let indices = (0..count).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
        let mesh = TriangleMesh::new(positions, indices).map_err(|e| self.err(span, e.to_string()))?;
        Ok(mesh.into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_seed_gives_the_same_triangles_everywhere() {
        let a = random_triangles(100, Vec3::ZERO, Vec3::splat(10.0), 0.5, 7);
        assert_eq!(a, random_triangles(100, Vec3::ZERO, Vec3::splat(10.0), 0.5, 7));
        assert_ne!(a, random_triangles(100, Vec3::ZERO, Vec3::splat(10.0), 0.5, 8));
        // The first numbers of PCG32 from state 42 on stream 54, as published with the
        // algorithm, and from `seed_from_u64(0)`, as rand_pcg's tests pin them: if an update of
        // the generator's crates changes either, every scene's triangles change.
        let mut r = Pcg32::new(42, 54);
        assert_eq!([r.next_u32(), r.next_u32(), r.next_u32()], [0xA15C_02B7, 0x7B47_F409, 0xBA1D_3330]);
        let mut r = Pcg32::seed_from_u64(0);
        assert_eq!([r.next_u32(), r.next_u32()], [0x11CD_D903, 0xFC84_3FD7]);
    }

    #[test]
    fn triangles_fill_the_box_and_have_the_size_asked() {
        let tris = random_triangles(20_000, Vec3::ZERO, Vec3::splat(10.0), 0.5, 1);
        let mut octants = [0usize; 8];
        for t in &tris {
            for v in t {
                for p in t {
                    assert!((*v - *p).abs().max_element() <= 0.5 + 1e-5);
                }
            }
            let c = (t[0] + t[1] + t[2]) / 3.0;
            octants[(c.x > 5.0) as usize + 2 * (c.y > 5.0) as usize + 4 * (c.z > 5.0) as usize] += 1;
        }
        // Uniform: every octant holds an eighth, give or take a few percent.
        for n in octants {
            assert!((2300..2700).contains(&n), "{octants:?}");
        }
    }
}
