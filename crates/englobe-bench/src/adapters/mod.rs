//! One adapter per library under test, each turning the harness's rays into the library's own
//! and its answers back into [`crate::library::RayResult`]s. Converting rays is part of every
//! timed query, the same for all: each library is used the way its own examples use it.

pub mod bvh;
#[cfg(feature = "embree")]
pub mod embree;
pub mod englobe;
pub mod moller_trumbore;
pub mod obvhs;
