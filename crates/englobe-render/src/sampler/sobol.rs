//! Owen-scrambled Sobol points, padded in groups of four dimensions: Burley 2020, "Practical
//! Hash-based Owen Scrambling" (JCGT 9(4)).
//!
//! Sobol's sequence (Sobol' 1967) in its first four dimensions, with the direction numbers of Joe
//! and Kuo 2008 ("Constructing Sobol sequences with better two-dimensional projections"), is a
//! (t, 4)-sequence whose first two dimensions are a (0, 2)-sequence: every aligned block of 2^m
//! points puts exactly one point in every elementary interval of area 2^-m. Dimensions beyond
//! four are padded: dimension `d` is dimension `d % 4` of a Sobol sequence whose point order is
//! shuffled by a seed of its group `d / 4`, so that groups are decorrelated while each keeps its
//! stratification. Every coordinate is then Owen-scrambled (a nested uniform scramble: each bit
//! flipped by a hash of the bits above it), which keeps those properties and makes each point
//! uniformly distributed. The scramble is the hash of Vegdahl 2021 ("Building a Better LK Hash"),
//! the one pbrt-v4's `FastOwenScrambler` uses.

/// The number of dimensions of the underlying Sobol sequence; further ones are padded.
pub const SOBOL_DIMENSIONS: u32 = 4;

/// Direction numbers of the first four Sobol dimensions, most significant bit first: dimension 0
/// is van der Corput's radical inverse; 1 to 3 follow the primitive polynomials `x + 1`,
/// `x^2 + x + 1` and `x^3 + x + 1` with Joe and Kuo's initial numbers `(1)`, `(1, 3)`, `(1, 3, 1)`.
const DIRECTIONS: [[u32; 32]; 4] = directions();

const fn directions() -> [[u32; 32]; 4] {
    let mut v = [[0u32; 32]; 4];
    let mut k = 0;
    while k < 32 {
        v[0][k] = 1 << (31 - k);
        k += 1;
    }
    // (degree s, coefficients a, initial m_1..m_s) for dimensions 1, 2 and 3.
    let polynomials: [(usize, u32, [u32; 3]); 3] = [(1, 0, [1, 0, 0]), (2, 1, [1, 3, 0]), (3, 1, [1, 3, 1])];
    let mut d = 0;
    while d < 3 {
        let (s, a, m) = polynomials[d];
        let mut k = 0;
        while k < 32 {
            v[d + 1][k] = if k < s {
                m[k] << (31 - k)
            } else {
                // Bratley and Fox 1988's recurrence:
                // v_k = a_1 v_{k-1} ^ ... ^ a_{s-1} v_{k-s+1} ^ v_{k-s} ^ (v_{k-s} >> s).
                let mut x = v[d + 1][k - s] ^ (v[d + 1][k - s] >> s);
                let mut i = 1;
                while i < s {
                    if (a >> (s - 1 - i)) & 1 == 1 {
                        x ^= v[d + 1][k - i];
                    }
                    i += 1;
                }
                x
            };
            k += 1;
        }
        d += 1;
    }
    v
}

/// Coordinate `dim` (below [`SOBOL_DIMENSIONS`]) of Sobol point `index`, as a 32-bit fraction.
#[inline]
pub fn sobol(index: u32, dim: u32) -> u32 {
    let v = &DIRECTIONS[dim as usize];
    let (mut bits, mut x) = (index, 0);
    while bits != 0 {
        x ^= v[bits.trailing_zeros() as usize];
        bits &= bits - 1;
    }
    x
}

/// A nested uniform scramble of the 32-bit fraction `x` (Vegdahl's hash on the reversed bits:
/// each step changes a bit only by the bits below it, so in `x`'s order every bit is flipped by
/// the bits above it).
#[inline]
pub fn owen_scramble(x: u32, seed: u32) -> u32 {
    let mut v = x.reverse_bits();
    v ^= v.wrapping_mul(0x3d20_adea);
    v = v.wrapping_add(seed);
    v = v.wrapping_mul((seed >> 16) | 1);
    v ^= v.wrapping_mul(0x0552_6c56);
    v ^= v.wrapping_mul(0x53a2_2864);
    v.reverse_bits()
}

/// A 64-bit mixing function (the finaliser of Steele et al. 2014's SplitMix64), for seeds.
#[inline]
pub fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Coordinate `dim` of point `index` of the padded, shuffled and scrambled sequence of `seed`,
/// as a 32-bit fraction.
#[inline]
pub fn scrambled_sobol(index: u32, dim: u32, seed: u64) -> u32 {
    let group = mix(seed ^ mix(u64::from(dim / SOBOL_DIMENSIONS) + 1));
    // Shuffling the order of the points with a nested scramble of the index permutes aligned
    // blocks of 2^m points among themselves, so each block stays a stratified set.
    let shuffled = owen_scramble(index, group as u32);
    let x = sobol(shuffled, dim % SOBOL_DIMENSIONS);
    owen_scramble(x, (group >> 32) as u32 ^ mix(group ^ u64::from(dim)) as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cell of a fraction among `2^bits` equal intervals.
    fn cell(x: u32, bits: u32) -> u32 {
        if bits == 0 { 0 } else { x >> (32 - bits) }
    }

    #[test]
    fn the_first_dimensions_are_the_known_sequence() {
        // Sobol's dimension 1 (x + 1, m = 1) starts 0, 1/2, 3/4, 1/4, 5/8, 1/8, 3/8, 7/8.
        let expected = [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875];
        for (i, e) in expected.iter().enumerate() {
            assert_eq!(sobol(i as u32, 1) as f64 / 2f64.powi(32), *e, "point {i}");
        }
        // Dimension 2 (x^2 + x + 1, m = 1, 3): 0, 1/2, 3/4, 1/4, 3/8, 7/8, 5/8, 1/8.
        let expected = [0.0, 0.5, 0.75, 0.25, 0.375, 0.875, 0.625, 0.125];
        for (i, e) in expected.iter().enumerate() {
            assert_eq!(sobol(i as u32, 2) as f64 / 2f64.powi(32), *e, "point {i}");
        }
        assert_eq!(sobol(5, 0), 0xa000_0000);
    }

    #[test]
    fn scrambling_is_a_permutation_that_keeps_the_top_bits_order_free() {
        // A nested scramble maps the 2^k intervals of size 2^-k onto each other one to one.
        for seed in [0, 1, 0xdead_beef] {
            for bits in 1..=8 {
                let mut seen = vec![false; 1 << bits];
                for i in 0..1u32 << bits {
                    let c = cell(owen_scramble(i << (32 - bits), seed), bits) as usize;
                    assert!(!seen[c], "seed {seed}, {bits} bits: two intervals onto {c}");
                    seen[c] = true;
                }
            }
        }
        assert_ne!(owen_scramble(0, 1), owen_scramble(0, 2));
    }

    #[test]
    fn padded_points_are_stratified_nets() {
        for seed in [0u64, 7, 123_456_789] {
            for m in 1..=8u32 {
                let n = 1u32 << m;
                // Every aligned block of 2^m points, in every dimension, one per 1/2^m interval.
                for block in [0, 1, 5] {
                    for dim in [0, 1, 2, 3, 4, 9, 30] {
                        let mut cells: Vec<u32> =
                            (0..n).map(|i| cell(scrambled_sobol(block * n + i, dim, seed), m)).collect();
                        cells.sort_unstable();
                        assert!(cells.iter().copied().eq(0..n), "seed {seed}, m {m}, block {block}, dim {dim}");
                    }
                    // Dimensions 4k and 4k + 1 together: a (0, m, 2)-net, one point in every
                    // elementary interval of 2^-i by 2^-(m - i).
                    for pair in [0, 4, 8] {
                        for i in 0..=m {
                            let mut cells: Vec<u32> = (0..n)
                                .map(|k| {
                                    let x = scrambled_sobol(block * n + k, pair, seed);
                                    let y = scrambled_sobol(block * n + k, pair + 1, seed);
                                    (cell(x, i) << (m - i)) | cell(y, m - i)
                                })
                                .collect();
                            cells.sort_unstable();
                            assert!(cells.iter().copied().eq(0..n), "seed {seed}, m {m}, pair {pair}, split {i}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn groups_and_seeds_are_decorrelated() {
        // Dimension 0 and dimension 4 are the same Sobol dimension in another order and scramble:
        // their points differ, and so do two pixels' (seeds').
        let a: Vec<u32> = (0..64).map(|i| scrambled_sobol(i, 0, 1)).collect();
        let b: Vec<u32> = (0..64).map(|i| scrambled_sobol(i, 4, 1)).collect();
        let c: Vec<u32> = (0..64).map(|i| scrambled_sobol(i, 0, 2)).collect();
        assert!(a.iter().zip(&b).filter(|(x, y)| x == y).count() < 4);
        assert!(a.iter().zip(&c).filter(|(x, y)| x == y).count() < 4);
        // The mean of many padded dimensions' first 256 points is 1/2 within their spread.
        let mean: f64 =
            (0..64).flat_map(|d| (0..256).map(move |i| scrambled_sobol(i, d, 99) as f64 / 2f64.powi(32))).sum::<f64>()
                / (64.0 * 256.0);
        assert!((mean - 0.5).abs() < 0.01, "{mean}");
    }
}
