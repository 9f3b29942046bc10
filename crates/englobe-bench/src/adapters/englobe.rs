//! englobe under test. The structure is chosen by name (`--englobe-accel`): any [`AccelKind`]
//! queried through [`World`] today, and the place to add a specialised fast path tomorrow: give
//! [`EnglobeStructure`] a variant, parse its name in [`EnglobeStructure::parse`], and build and
//! query it in [`EnglobeLibrary`]; the harness, the agreement checks and the tables need nothing
//! else.

use std::fmt;

use englobe::{AccelKind, NoCount, Object, World};

use crate::library::{Library, RayResult};
use crate::rays::BenchRay;
use crate::scene::BenchScene;

/// The structures englobe can be measured with, best first: the default is the first one this
/// build of englobe knows.
pub const PREFERRED: &[&str] = &["bvh-sah", "bvh-seed-ordered"];

/// Which englobe structure to measure.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnglobeStructure {
    /// A structure of [`AccelKind`], queried through [`World`] with a mesh object.
    World(AccelKind),
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
        name.parse::<AccelKind>().map(EnglobeStructure::World).map_err(|e| e.to_string())
    }

    /// Its name, as `--englobe-accel` takes it.
    pub fn name(&self) -> String {
        match self {
            EnglobeStructure::World(kind) => kind.name().to_owned(),
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
    world: World,
}

impl EnglobeLibrary {
    /// Builds `structure` over the scene's mesh.
    pub fn build(scene: &BenchScene, structure: EnglobeStructure) -> anyhow::Result<Self> {
        match structure {
            EnglobeStructure::World(kind) => {
                let world = World::build(vec![Object::Mesh(scene.mesh.clone())], kind)?;
                Ok(EnglobeLibrary { structure, world })
            }
        }
    }
}

impl Library for EnglobeLibrary {
    fn structure(&self) -> String {
        match self.structure {
            EnglobeStructure::World(kind) => format!("{} through World", kind.name()),
        }
    }

    fn closest_hits(&self, rays: &[BenchRay], out: &mut [RayResult]) {
        for (ray, out) in rays.iter().zip(out) {
            *out = match self.world.closest_hit(&ray.to_englobe(), &mut NoCount) {
                Some(hit) => RayResult::hit(hit.t, hit.prim),
                None => RayResult::MISS,
            };
        }
    }

    fn any_hits(&self, rays: &[BenchRay], out: &mut [bool]) {
        for (ray, out) in rays.iter().zip(out) {
            *out = self.world.any_hit(&ray.to_englobe(), &mut NoCount);
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
        assert!(EnglobeStructure::parse("octree").is_err());
    }
}
