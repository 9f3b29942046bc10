//! The registry of the libraries under test: their names ([`LibraryKind`]), how to build them
//! ([`BuildSettings`]) and [`build_library`], which builds each through its adapter in
//! [`crate::adapters`]. The one module that knows every adapter.

use std::fmt;
use std::str::FromStr;

use crate::adapters;
use crate::adapters::englobe::EnglobeStructure;
use crate::library::Library;
use crate::scene::BenchScene;

/// The libraries, by the names the CSV uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum LibraryKind {
    /// Intel Embree 3, one ray at a time (`rtcIntersect1`, `rtcOccluded1`).
    Embree,
    /// Intel Embree 3, 16-ray packets (`rtcIntersect16`, `rtcOccluded16`).
    EmbreePacket16,
    /// englobe's structure under test.
    Englobe,
    /// englobe's triangle BVH, 16-ray packets (`TriangleBvh::closest_hit_packet`).
    EnglobePacket16,
    /// obvhs 0.4, compressed wide BVH (CwBvh).
    Obvhs,
    /// bvh 0.13 (svenstaro/bvh).
    Bvh,
}

impl LibraryKind {
    /// Every library, in table order.
    pub const ALL: [LibraryKind; 6] = [
        LibraryKind::Embree,
        LibraryKind::EmbreePacket16,
        LibraryKind::Englobe,
        LibraryKind::EnglobePacket16,
        LibraryKind::Obvhs,
        LibraryKind::Bvh,
    ];

    /// The name in tables and the CSV.
    pub fn name(self) -> &'static str {
        match self {
            LibraryKind::Embree => "embree",
            LibraryKind::EmbreePacket16 => "embree-packet16",
            LibraryKind::Englobe => "englobe",
            LibraryKind::EnglobePacket16 => "englobe-packet16",
            LibraryKind::Obvhs => "obvhs",
            LibraryKind::Bvh => "bvh",
        }
    }

    /// Whether this build can run it (Embree needs the `embree` feature).
    pub fn available(self) -> bool {
        cfg!(feature = "embree") || !matches!(self, LibraryKind::Embree | LibraryKind::EmbreePacket16)
    }

    /// The libraries this build can run, in table order.
    pub fn available_kinds() -> Vec<LibraryKind> {
        LibraryKind::ALL.into_iter().filter(|k| k.available()).collect()
    }
}

impl fmt::Display for LibraryKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for LibraryKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let kind = LibraryKind::ALL.into_iter().find(|k| k.name() == s).ok_or_else(|| {
            let names: Vec<_> = LibraryKind::ALL.iter().map(|k| k.name()).collect();
            format!("unknown library `{s}`; expected one of: {}", names.join(", "))
        })?;
        if !kind.available() {
            return Err(format!("`{s}` needs the `embree` cargo feature (and Debian's libembree-dev)"));
        }
        Ok(kind)
    }
}

/// How to build the libraries.
#[derive(Clone, Copy, Debug)]
pub struct BuildSettings {
    /// Threads the build may use (the harness also runs it inside a pool of this size).
    pub threads: usize,
    /// englobe's structure.
    pub englobe: EnglobeStructure,
    /// Build Embree's scene with `RTC_SCENE_FLAG_ROBUST` (off by default).
    pub embree_robust: bool,
}

/// Builds library `kind` over the scene's triangles. Call it inside the thread pool the
/// measurement uses, so that builders parallelised with rayon use that many threads.
pub fn build_library(
    kind: LibraryKind,
    scene: &BenchScene,
    settings: &BuildSettings,
) -> anyhow::Result<Box<dyn Library>> {
    Ok(match kind {
        LibraryKind::Englobe => Box::new(adapters::englobe::EnglobeLibrary::build(scene, settings.englobe)?),
        LibraryKind::EnglobePacket16 => {
            Box::new(adapters::englobe::EnglobeLibrary::build_packets(scene, settings.englobe)?)
        }
        LibraryKind::Obvhs => Box::new(adapters::obvhs::ObvhsLibrary::build(scene)),
        LibraryKind::Bvh => Box::new(adapters::bvh::BvhLibrary::build(scene)),
        #[cfg(feature = "embree")]
        LibraryKind::Embree => {
            Box::new(adapters::embree::EmbreeSingle::build(scene, settings.threads, settings.embree_robust)?)
        }
        #[cfg(feature = "embree")]
        LibraryKind::EmbreePacket16 => {
            Box::new(adapters::embree::EmbreePacket16::build(scene, settings.threads, settings.embree_robust)?)
        }
        #[cfg(not(feature = "embree"))]
        LibraryKind::Embree | LibraryKind::EmbreePacket16 => {
            anyhow::bail!("{kind} needs the `embree` cargo feature (and Debian's libembree-dev)")
        }
    })
}
