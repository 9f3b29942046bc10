//! The instruction sets the wide BVH's kernels are compiled for, chosen at run time, so that one
//! binary runs on any x86-64 (and any other target) and uses the widest vectors the processor has.
//!
//! * [`Isa::Portable`]: four lanes through glam's `Vec4`, which is SSE2 on x86-64, NEON on
//!   aarch64 and plain scalar code elsewhere. Always available.
//! * [`Isa::Avx2`]: eight lanes (x86-64 with AVX2 and FMA, and BMI1, BMI2, LZCNT and POPCNT,
//!   which every such processor has: x86-64-v3).
//! * [`Isa::Avx512`]: eight lanes with AVX-512's mask registers and compress instructions
//!   (x86-64 with AVX-512 F, VL, BW and DQ).
//!
//! Every kernel computes the same slab and triangle tests with the same operations in the same
//! order, so every choice gives identical answers; the tests run each available one. The choice
//! is made once per structure (at build, [`Isa::best`]), and can be narrowed afterwards, for
//! tests and measurements, to any instruction set [`Isa::is_available`] says the processor has.

use std::fmt;
use std::sync::OnceLock;

/// An instruction set for the wide BVH's kernels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Isa {
    /// Four lanes via glam (SSE2, NEON or scalar): runs everywhere.
    Portable,
    /// AVX2 and FMA, with BMI1, BMI2, LZCNT and POPCNT (x86-64-v3).
    Avx2,
    /// AVX-512 F, VL, BW and DQ (x86-64).
    Avx512,
}

impl Isa {
    /// Every instruction set, narrowest first.
    pub const ALL: [Isa; 3] = [Isa::Portable, Isa::Avx2, Isa::Avx512];

    /// Its name in tables.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Portable => "portable",
            Isa::Avx2 => "avx2",
            Isa::Avx512 => "avx512",
        }
    }

    /// Whether this processor can run it (detected once, then cached).
    pub fn is_available(self) -> bool {
        static DETECTED: OnceLock<[bool; 3]> = OnceLock::new();
        let detected = DETECTED.get_or_init(|| [true, detect_avx2(), detect_avx512()]);
        detected[self as usize]
    }

    /// The instruction sets this processor can run, narrowest first.
    pub fn available() -> Vec<Isa> {
        Isa::ALL.into_iter().filter(|i| i.is_available()).collect()
    }

    /// The widest available instruction set that measured fastest (see `docs/performance.md`),
    /// or the narrower one that the environment variable `ENGLOBE_ISA` names (`portable`,
    /// `avx2`), for measuring a narrower processor's kernels on a wider one. A name this
    /// processor cannot run, or not an instruction set's, leaves the widest. Read once.
    pub fn best() -> Isa {
        static CHOSEN: OnceLock<Isa> = OnceLock::new();
        *CHOSEN.get_or_init(|| Isa::chosen(Isa::widest(), std::env::var("ENGLOBE_ISA").ok().as_deref()))
    }

    /// The widest instruction set this processor can run.
    fn widest() -> Isa {
        if Isa::Avx512.is_available() {
            Isa::Avx512
        } else if Isa::Avx2.is_available() {
            Isa::Avx2
        } else {
            Isa::Portable
        }
    }

    /// `widest`, or the available instruction set no wider than it that `asked` names.
    fn chosen(widest: Isa, asked: Option<&str>) -> Isa {
        Isa::ALL.into_iter().find(|i| Some(i.name()) == asked && *i <= widest && i.is_available()).unwrap_or(widest)
    }
}

impl fmt::Display for Isa {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// An instruction set this processor lacks was asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("this processor cannot run the {0} kernels")]
pub struct IsaUnavailable(pub Isa);

#[cfg(target_arch = "x86_64")]
fn detect_avx2() -> bool {
    // The bit instructions (popcount, trailing zeros, BMI2's shifts) that every processor with
    // AVX2 and FMA has (x86-64-v3): the walks count and pick rays and children by their bits.
    is_x86_feature_detected!("avx2")
        && is_x86_feature_detected!("fma")
        && is_x86_feature_detected!("bmi1")
        && is_x86_feature_detected!("bmi2")
        && is_x86_feature_detected!("lzcnt")
        && is_x86_feature_detected!("popcnt")
}

#[cfg(target_arch = "x86_64")]
fn detect_avx512() -> bool {
    detect_avx2()
        && is_x86_feature_detected!("avx512f")
        && is_x86_feature_detected!("avx512vl")
        && is_x86_feature_detected!("avx512bw")
        && is_x86_feature_detected!("avx512dq")
}

#[cfg(not(target_arch = "x86_64"))]
fn detect_avx2() -> bool {
    false
}

#[cfg(not(target_arch = "x86_64"))]
fn detect_avx512() -> bool {
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_portable_kernels_are_always_available_and_best_is_available() {
        assert!(Isa::Portable.is_available());
        assert!(Isa::best().is_available());
        assert_eq!(Isa::available()[0], Isa::Portable);
        // AVX-512 implies AVX2: the dispatch relies on it.
        assert!(!Isa::Avx512.is_available() || Isa::Avx2.is_available());
    }

    #[test]
    fn the_environment_narrows_the_choice_and_never_widens_it() {
        let widest = Isa::widest();
        assert_eq!(Isa::chosen(widest, None), widest);
        assert_eq!(Isa::chosen(widest, Some("portable")), Isa::Portable);
        assert_eq!(Isa::chosen(Isa::Portable, Some("avx512")), Isa::Portable);
        assert_eq!(Isa::chosen(widest, Some("sse9")), widest);
        assert_eq!(Isa::chosen(widest, Some("AVX2")), widest, "names are matched exactly");
        if Isa::Avx2.is_available() {
            assert_eq!(Isa::chosen(widest, Some("avx2")), Isa::Avx2);
        }
    }
}
