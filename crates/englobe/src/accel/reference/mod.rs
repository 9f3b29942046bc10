//! The seed report's own structure and the two yardsticks, apart from the field's structures so
//! that a reader sees which is which:
//!
//! * [`brute`]: no structure ([`BruteForce`]); the oracle every other one is checked against.
//! * [`seed_pairing`]: the report's BVH builder, the `x + y + z` pairing ([`SeedPairing`]).
//! * [`candidates`]: the report's traversal, a candidate list tested after the walk
//!   ([`CandidateListBvh`]).
//! * [`bound`]: the fewest exact tests any BVH over the same boxes could make ([`LowerBound`]).

pub mod bound;
pub mod brute;
pub mod candidates;
pub mod seed_pairing;

pub use bound::LowerBound;
pub use brute::BruteForce;
pub use candidates::CandidateListBvh;
pub use seed_pairing::SeedPairing;
