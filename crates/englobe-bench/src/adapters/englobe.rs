//! englobe under test. The structure is chosen by name (`--englobe-accel`): the triangle fast
//! path [`TriangleBvh`] (`triangle-bvh`, the default; `triangle-bvh-avx2` and so on to pin an
//! instruction set; `--englobe-presplit` sets its pre-split budget), or any [`AccelKind`] queried
//! through [`World`]. To add another: give
//! [`EnglobeStructure`] a variant, parse its name in [`EnglobeStructure::parse`], and build and
//! query it in [`EnglobeLibrary`]; the harness, the agreement checks and the tables need nothing
//! else.
//!
//! Queries run with the zero-sized [`NoCount`], so counting compiles away, and allocate nothing:
//! the traversal's stack lives on the call stack.

use std::fmt;

use englobe::accel::wide::Isa;
use englobe::accel::wide::packet_kernels::PACKET;
use englobe::accel::wide::triangle_bvh::TriangleBvhOptions;
use englobe::{AccelKind, NoCount, Object, PacketHits, RayPacket, TriangleBvh, World};

use crate::library::{BenchRay, Library, RayResult};
use crate::scene::BenchScene;

/// The structures englobe can be measured with, best first: the default is the first one this
/// build of englobe knows.
pub const PREFERRED: &[&str] = &["triangle-bvh", "bvh-sah", "bvh-seed-ordered"];

/// The name of the triangle fast path.
const TRIANGLE_BVH: &str = "triangle-bvh";

/// Which englobe structure to measure.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnglobeStructure {
    /// A structure of [`AccelKind`], queried through [`World`] with a mesh object.
    World(AccelKind),
    /// The wide BVH over blocks of triangles, with the processor's best instruction set or the
    /// one given, and the library's pre-split budget or the one given.
    Triangles {
        /// The instruction set, if not the processor's best.
        isa: Option<Isa>,
        /// [`TriangleBvhOptions::presplit_percent`], if not the library's default: the pre-split
        /// with that budget, and no spatial splits.
        presplit_percent: Option<u32>,
    },
}

impl EnglobeStructure {
    /// The best structure available: the first of [`PREFERRED`] that parses.
    pub fn best() -> Self {
        PREFERRED
            .iter()
            .find_map(|name| Self::parse(name).ok())
            .unwrap_or(EnglobeStructure::World(AccelKind::BvhSeedOrdered))
    }

    /// The structure called `name`.
    pub fn parse(name: &str) -> Result<Self, String> {
        if name == TRIANGLE_BVH {
            return Ok(EnglobeStructure::Triangles { isa: None, presplit_percent: None });
        }
        if let Some(isa) = name.strip_prefix(TRIANGLE_BVH).and_then(|rest| rest.strip_prefix('-')) {
            let isa = Isa::ALL.into_iter().find(|i| i.name() == isa).ok_or_else(|| {
                let names: Vec<_> = Isa::ALL.iter().map(|i| format!("{TRIANGLE_BVH}-{i}")).collect();
                format!("unknown instruction set in `{name}`; expected one of: {}", names.join(", "))
            })?;
            if !isa.is_available() {
                return Err(format!("`{name}`: this processor cannot run the {isa} kernels"));
            }
            return Ok(EnglobeStructure::Triangles { isa: Some(isa), presplit_percent: None });
        }
        name.parse::<AccelKind>()
            .map(EnglobeStructure::World)
            .map_err(|e| format!("{e}, or {TRIANGLE_BVH} (optionally -portable, -avx2 or -avx512)"))
    }

    /// Its name, as `--englobe-accel` takes it.
    pub fn name(&self) -> String {
        match self {
            EnglobeStructure::World(kind) => kind.name().to_owned(),
            EnglobeStructure::Triangles { isa: None, .. } => TRIANGLE_BVH.to_owned(),
            EnglobeStructure::Triangles { isa: Some(isa), .. } => format!("{TRIANGLE_BVH}-{isa}"),
        }
    }

    /// The same structure built with a pre-split budget of `percent` (the triangle BVH only).
    pub fn with_presplit(self, percent: u32) -> Result<Self, String> {
        match self {
            EnglobeStructure::Triangles { isa, .. } => {
                Ok(EnglobeStructure::Triangles { isa, presplit_percent: Some(percent) })
            }
            EnglobeStructure::World(kind) => {
                Err(format!("--englobe-presplit: `{}` has no pre-split; only {TRIANGLE_BVH} has", kind.name()))
            }
        }
    }
}

impl Default for EnglobeStructure {
    /// The best structure available ([`EnglobeStructure::best`]).
    fn default() -> Self {
        Self::best()
    }
}

impl fmt::Display for EnglobeStructure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

/// englobe, built.
pub struct EnglobeLibrary {
    structure: EnglobeStructure,
    built: Built,
    /// Whether queries trace 16-ray packets (`TriangleBvh` only).
    packets: bool,
}

/// The structure itself.
enum Built {
    World(Box<World>),
    Triangles(TriangleBvh),
}

impl EnglobeLibrary {
    /// Builds `structure` over the scene's mesh.
    pub fn build(scene: &BenchScene, structure: EnglobeStructure) -> anyhow::Result<Self> {
        match structure {
            EnglobeStructure::World(kind) => {
                let world = World::build(vec![Object::Mesh(scene.mesh.clone())], kind)?;
                Ok(EnglobeLibrary { structure, built: Built::World(Box::new(world)), packets: false })
            }
            EnglobeStructure::Triangles { isa, presplit_percent } => {
                let defaults = TriangleBvhOptions::default();
                // A budget given is the pre-split's alone, with no spatial splits.
                let options = match presplit_percent {
                    Some(percent) => TriangleBvhOptions { presplit_percent: percent, spatial_levels: 0, ..defaults },
                    None => defaults,
                };
                let mesh = &scene.mesh;
                let mut bvh = TriangleBvh::build_with(mesh.len(), |i| mesh.triangle(i).vertices, options);
                if let Some(isa) = isa {
                    bvh.set_isa(isa)?;
                }
                Ok(EnglobeLibrary { structure, built: Built::Triangles(bvh), packets: false })
            }
        }
    }

    /// Builds `structure`, which must be the triangle BVH, for queries in 16-ray packets: each
    /// group of 16 rays the harness hands over is traced as one packet, as Embree's
    /// `rtcIntersect16` is.
    pub fn build_packets(scene: &BenchScene, structure: EnglobeStructure) -> anyhow::Result<Self> {
        let structure = match structure {
            EnglobeStructure::World(_) => EnglobeStructure::Triangles { isa: None, presplit_percent: None },
            triangles => triangles,
        };
        Ok(EnglobeLibrary { packets: true, ..Self::build(scene, structure)? })
    }
}

/// Puts up to [`RayPacket::LANES`] rays into `packet`'s rows, as the Embree adapter fills its
/// `RTCRay16`; returns the mask of the lanes filled.
fn fill_packet(rays: &[BenchRay], packet: &mut RayPacket) -> u32 {
    for (lane, r) in rays.iter().enumerate().take(RayPacket::LANES) {
        packet.set(lane, r.origin, r.dir, r.t_min, r.t_max);
    }
    (1u32 << rays.len().min(RayPacket::LANES)) - 1
}

impl Library for EnglobeLibrary {
    fn packet_width(&self) -> usize {
        if self.packets { PACKET } else { 1 }
    }

    fn structure(&self) -> String {
        let presplit = match self.structure {
            EnglobeStructure::Triangles { presplit_percent: Some(p), .. } => format!("; pre-split {p} %"),
            _ => String::new(),
        };
        if let (true, Built::Triangles(bvh)) = (self.packets, &self.built) {
            return format!("{TRIANGLE_BVH} ({}{presplit}), 16-ray packets", bvh.isa());
        }
        match (&self.structure, &self.built) {
            (EnglobeStructure::World(kind), _) => format!("{} through World", kind.name()),
            (_, Built::Triangles(bvh)) => format!("{TRIANGLE_BVH} ({}{presplit})", bvh.isa()),
            (_, Built::World(_)) => self.structure.name(),
        }
    }

    fn closest_hits(&self, rays: &[BenchRay], out: &mut [RayResult]) {
        if let (true, Built::Triangles(bvh)) = (self.packets, &self.built) {
            let mut packet = RayPacket::default();
            for (rays, out) in rays.chunks(PACKET).zip(out.chunks_mut(PACKET)) {
                let active = fill_packet(rays, &mut packet);
                let hits = bvh.closest_hit_ray_packet(&packet, active, &mut NoCount);
                for (lane, o) in out.iter_mut().enumerate() {
                    *o = match hits.prim[lane] {
                        PacketHits::MISS => RayResult::MISS,
                        prim => RayResult::hit(hits.t[lane], prim),
                    };
                }
            }
            return;
        }
        match &self.built {
            Built::World(world) => {
                for (ray, out) in rays.iter().zip(out) {
                    let hit = world.closest_hit(&ray.to_englobe(), &mut NoCount);
                    *out = hit.map_or(RayResult::MISS, |h| RayResult::hit(h.t, h.prim));
                }
            }
            Built::Triangles(bvh) => {
                for (ray, out) in rays.iter().zip(out) {
                    let hit = bvh.closest_hit(&ray.to_englobe(), &mut NoCount);
                    *out = hit.map_or(RayResult::MISS, |h| RayResult::hit(h.t, h.prim));
                }
            }
        }
    }

    fn any_hits(&self, rays: &[BenchRay], out: &mut [bool]) {
        if let (true, Built::Triangles(bvh)) = (self.packets, &self.built) {
            let mut packet = RayPacket::default();
            for (rays, out) in rays.chunks(PACKET).zip(out.chunks_mut(PACKET)) {
                let active = fill_packet(rays, &mut packet);
                let hit = bvh.any_hit_ray_packet(&packet, active, &mut NoCount);
                for (lane, o) in out.iter_mut().enumerate() {
                    *o = hit >> lane & 1 != 0;
                }
            }
            return;
        }
        match &self.built {
            Built::World(world) => {
                for (ray, out) in rays.iter().zip(out) {
                    *out = world.any_hit(&ray.to_englobe(), &mut NoCount);
                }
            }
            Built::Triangles(bvh) => {
                for (ray, out) in rays.iter().zip(out) {
                    *out = bvh.any_hit(&ray.to_englobe(), &mut NoCount);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_best_structure_is_known_and_names_round_trip() {
        let best = EnglobeStructure::best();
        assert_eq!(EnglobeStructure::parse(&best.name()).unwrap(), best);
        assert_eq!(best, EnglobeStructure::Triangles { isa: None, presplit_percent: None });
        assert!(EnglobeStructure::parse("octree").is_err());
        assert!(EnglobeStructure::parse("triangle-bvh-sse9").is_err());
        for isa in Isa::available() {
            let s = EnglobeStructure::parse(&format!("triangle-bvh-{isa}")).unwrap();
            assert_eq!(
                (s, EnglobeStructure::parse(&s.name()).unwrap()),
                (EnglobeStructure::Triangles { isa: Some(isa), presplit_percent: None }, s)
            );
        }
    }

    #[test]
    fn the_presplit_budget_reaches_the_build_and_the_label() {
        let meshes =
            englobe_scene::shared_data::shared_meshes_or_panic(std::path::Path::new(env!("CARGO_MANIFEST_DIR")));
        let scene = BenchScene::load("sponza", &meshes.join("sponza-dabrovic/sponza.obj"), None).unwrap();
        let references = |presplit_percent| {
            let structure = EnglobeStructure::Triangles { isa: None, presplit_percent };
            let library = EnglobeLibrary::build(&scene, structure).unwrap();
            let Built::Triangles(bvh) = &library.built else { panic!("a triangle BVH") };
            (bvh.stats().prim_refs, library.structure())
        };
        let triangles = scene.mesh.len();
        // The atrium's walls and floors are long triangles whose boxes waste area: the default
        // build cuts some of them (by spatial splits), a pre-split budget of 0 none.
        let (default_refs, default_label) = references(None);
        let (uncut, uncut_label) = references(Some(0));
        assert!(default_refs > triangles, "{default_refs} references for {triangles} triangles");
        assert_eq!(uncut, triangles);
        assert!(!default_label.contains("pre-split"), "{default_label}");
        assert!(uncut_label.ends_with("; pre-split 0 %)"), "{uncut_label}");
        let world = EnglobeStructure::parse("bvh-sah").unwrap();
        assert!(world.with_presplit(0).unwrap_err().contains("only triangle-bvh"));
    }
}
