//! What a render counted: rays cast and the structure's work, per kind of ray. The seed report
//! measured exactly this (calls to the exact intersection function, over all rays of an image).

use englobe::{Counters, WorkCounts};
use serde::Serialize;

/// The kinds of rays the integrators cast.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum RayKind {
    /// From the camera through a pixel.
    Primary,
    /// From a hit point toward a light.
    Shadow,
    /// Mirror reflections.
    Reflected,
    /// Transmission through transparent surfaces.
    Refracted,
    /// Diffuse bounces of the path tracer (random directions over the hemisphere).
    Bounce,
}

impl RayKind {
    /// Number of kinds.
    pub const COUNT: usize = 5;

    /// Every kind, in table order.
    pub const ALL: [RayKind; RayKind::COUNT] =
        [RayKind::Primary, RayKind::Shadow, RayKind::Reflected, RayKind::Refracted, RayKind::Bounce];

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            RayKind::Primary => "primary",
            RayKind::Shadow => "shadow",
            RayKind::Reflected => "reflected",
            RayKind::Refracted => "refracted",
            RayKind::Bounce => "bounce",
        }
    }
}

/// Rays and work of one kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct KindStats {
    /// Rays cast.
    pub rays: u64,
    /// Exact ray/primitive tests (the seed's measure).
    pub exact_tests: u64,
    /// Structure nodes visited.
    pub nodes_visited: u64,
    /// Ray/box tests.
    pub box_tests: u64,
}

impl KindStats {
    fn add(&mut self, o: &KindStats) {
        self.rays += o.rays;
        self.exact_tests += o.exact_tests;
        self.nodes_visited += o.nodes_visited;
        self.box_tests += o.box_tests;
    }
}

/// Rays and work per kind of ray, for a whole render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderStats {
    /// Indexed by `RayKind as usize`.
    pub kinds: [KindStats; RayKind::COUNT],
}

impl RenderStats {
    /// The counts of one kind.
    pub fn kind(&self, kind: RayKind) -> &KindStats {
        &self.kinds[kind as usize]
    }

    /// All kinds summed.
    pub fn total(&self) -> KindStats {
        let mut t = KindStats::default();
        self.kinds.iter().for_each(|k| t.add(k));
        t
    }

    /// Adds another render's (or tile's) counts.
    pub fn add(&mut self, o: &RenderStats) {
        for (a, b) in self.kinds.iter_mut().zip(&o.kinds) {
            a.add(b);
        }
    }
}

/// Per-kind ray counts plus a work sink of type `C` per kind, kept by each worker during a render
/// and folded into [`RenderStats`]. With [`englobe::NoCount`] the work sinks vanish.
#[derive(Debug, Default)]
pub struct Tally<C: Counters> {
    /// Rays cast, by kind.
    pub rays: [u64; RayKind::COUNT],
    /// Work, by kind.
    pub work: [C; RayKind::COUNT],
}

impl<C: Counters + Into<WorkCounts> + Copy> Tally<C> {
    /// The work of all kinds of rays so far, summed.
    #[inline]
    pub fn work_total(&self) -> WorkCounts {
        let mut total = WorkCounts::default();
        for w in &self.work {
            total += (*w).into();
        }
        total
    }

    /// The counts as statistics.
    pub fn stats(&self) -> RenderStats {
        let mut s = RenderStats::default();
        for (i, k) in s.kinds.iter_mut().enumerate() {
            let w: WorkCounts = self.work[i].into();
            *k = KindStats {
                rays: self.rays[i],
                exact_tests: w.exact_tests,
                nodes_visited: w.nodes_visited,
                box_tests: w.box_tests,
            };
        }
        s
    }
}
