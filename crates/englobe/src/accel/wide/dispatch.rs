//! The one place where a query picks its compiled kernels: a `match` on the structure's
//! instruction set, each arm a copy of the traversal compiled with that set's target features
//! (`#[target_feature]`, so one binary carries them all and runs on any x86-64). With AVX-512, a
//! single-ray query whose ray the fused node test applies to (see [`super::fused`]) takes a
//! copy of the walk compiled with it, the others the exact-order test's copy: the choice is made
//! before the call, so that each copy keeps its own registers.
//!
//! Soundness: the AVX2 and AVX-512 copies may only run on processors that have those features.
//! A structure's [`Isa`] is chosen by [`Isa::best`] or changed only through a setter that checks
//! [`Isa::is_available`], so an arm is only ever taken on a processor that can run it.

#[cfg(target_arch = "x86_64")]
use super::fused;
use super::isa::Isa;
use super::kernels::{NodeKernel, Portable};
use super::node::{NodeRay, WideNode};
use super::packet::{self, PacketLeaves};
use super::packet_kernels::{PacketRays, ScalarPacket};
use super::packet_prep::{Lanes4, PacketPrep};
use super::traverse::{self, Leaves};
use crate::accel::Counters;

/// The closest-hit traversal compiled for `isa`, which the processor must have (see the module
/// documentation), from node `start` (0, the root, for a whole query).
#[inline(always)]
pub fn closest<C: Counters, L: Leaves<C>>(
    isa: Isa,
    nodes: &[WideNode],
    depth: u32,
    start: u32,
    ray: &NodeRay,
    leaves: &mut L,
    counters: &mut C,
) {
    debug_assert!(isa.is_available());
    match isa {
        Isa::Portable => portable::closest(nodes, depth, start, ray, leaves, counters),
        // SAFETY: the structure's instruction set is one the processor has (module documentation).
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { x86::closest_avx2(nodes, depth, start, ray, leaves, counters) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 if fused::applies_to(ray) => unsafe {
            x86::closest_avx512(x86::FUSED, nodes, depth, start, ray, leaves, counters)
        },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { x86::closest_avx512(x86::Avx512, nodes, depth, start, ray, leaves, counters) },
        #[cfg(not(target_arch = "x86_64"))]
        _ => unreachable!("x86 instruction sets are never available elsewhere"),
    }
}

/// The any-hit traversal compiled for `isa` (see [`closest`]).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn any<C: Counters, L: Leaves<C>>(
    isa: Isa,
    nodes: &[WideNode],
    depth: u32,
    start: u32,
    ray: &NodeRay,
    limit: f32,
    leaves: &mut L,
    counters: &mut C,
) -> bool {
    debug_assert!(isa.is_available());
    match isa {
        Isa::Portable => portable::any(nodes, depth, start, ray, limit, leaves, counters),
        // SAFETY: the structure's instruction set is one the processor has (module documentation).
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { x86::any_avx2(nodes, depth, start, ray, limit, leaves, counters) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 if fused::applies_to(ray) => unsafe {
            x86::any_avx512(x86::FUSED, nodes, depth, start, ray, limit, leaves, counters)
        },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { x86::any_avx512(x86::Avx512, nodes, depth, start, ray, limit, leaves, counters) },
        #[cfg(not(target_arch = "x86_64"))]
        _ => unreachable!("x86 instruction sets are never available elsewhere"),
    }
}

/// The packet closest-hit traversal compiled for `isa` (see [`closest`]); `depth` must
/// [`packet::fits`].
#[inline(always)]
pub fn closest_packet<C: Counters, L: PacketLeaves<C>>(
    isa: Isa,
    nodes: &[WideNode],
    rays: &PacketRays,
    active: u32,
    leaves: &mut L,
    counters: &mut C,
) {
    debug_assert!(isa.is_available());
    match isa {
        Isa::Portable => portable::closest_packet(nodes, rays, active, leaves, counters),
        // SAFETY: the structure's instruction set is one the processor has (module documentation).
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { x86::closest_packet_avx2(nodes, rays, active, leaves, counters) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { x86::closest_packet_avx512(nodes, rays, active, leaves, counters) },
        #[cfg(not(target_arch = "x86_64"))]
        _ => unreachable!("x86 instruction sets are never available elsewhere"),
    }
}

/// The packet any-hit traversal compiled for `isa` (see [`closest_packet`]): the rays that hit.
#[inline(always)]
pub fn any_packet<C: Counters, L: PacketLeaves<C>>(
    isa: Isa,
    nodes: &[WideNode],
    rays: &PacketRays,
    active: u32,
    leaves: &mut L,
    counters: &mut C,
) -> u32 {
    debug_assert!(isa.is_available());
    match isa {
        Isa::Portable => portable::any_packet(nodes, rays, active, leaves, counters),
        // SAFETY: the structure's instruction set is one the processor has (module documentation).
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { x86::any_packet_avx2(nodes, rays, active, leaves, counters) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { x86::any_packet_avx512(nodes, rays, active, leaves, counters) },
        #[cfg(not(target_arch = "x86_64"))]
        _ => unreachable!("x86 instruction sets are never available elsewhere"),
    }
}

/// The packet closest-hit traversal compiled for AVX-512, for leaves whose tests are compiled
/// into it with those features (see [`super::packet_triangles::block_avx512`]).
///
/// # Safety
/// The processor has AVX-512 F, VL, BW and DQ ([`Isa::Avx512`] is available), and `depth`
/// [`packet::fits`].
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub unsafe fn closest_packet_avx512<C: Counters, L: PacketLeaves<C>>(
    nodes: &[WideNode],
    rays: &PacketRays,
    active: u32,
    leaves: &mut L,
    counters: &mut C,
) {
    debug_assert!(Isa::Avx512.is_available());
    // SAFETY: the caller's guarantee.
    unsafe { x86::closest_packet_avx512(nodes, rays, active, leaves, counters) }
}

/// The packet any-hit traversal compiled for AVX-512 (see [`closest_packet_avx512`]): the rays
/// that hit.
///
/// # Safety
/// As [`closest_packet_avx512`].
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub unsafe fn any_packet_avx512<C: Counters, L: PacketLeaves<C>>(
    nodes: &[WideNode],
    rays: &PacketRays,
    active: u32,
    leaves: &mut L,
    counters: &mut C,
) -> u32 {
    debug_assert!(Isa::Avx512.is_available());
    // SAFETY: the caller's guarantee.
    unsafe { x86::any_packet_avx512(nodes, rays, active, leaves, counters) }
}

/// A whole packet query, from the rays as the caller hands them over to the answers: compiled by
/// [`packet_query`] with the structure's instruction set, so that the rays' preparation (the
/// inverse directions, the checks, the packet's bounds) runs with the same vector instructions as
/// the walk rather than the target's baseline.
pub trait PacketQuery {
    /// What the query returns.
    type Output;
    /// Runs the query, its rays prepared by `prep`, made for the copy's instruction set.
    /// Implementations are `#[inline(always)]`, so that their body is compiled into the copy that
    /// calls them (a closure would be compiled without its features).
    ///
    /// # Safety
    /// As [`PacketPrep::prepare_rows`]: compiled with the preparation's target features, run on a
    /// processor that has them.
    unsafe fn run<P: PacketPrep>(self, prep: P) -> Self::Output;
}

/// Runs `query` compiled for `isa`, which the processor must have (see the module documentation).
#[inline(always)]
pub fn packet_query<Q: PacketQuery>(isa: Isa, query: Q) -> Q::Output {
    debug_assert!(isa.is_available());
    match isa {
        // SAFETY: the portable preparation needs nothing beyond the target's baseline.
        Isa::Portable => unsafe { query.run(Lanes4) },
        // SAFETY: the structure's instruction set is one the processor has (module documentation).
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { x86::packet_query_avx2(query) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { x86::packet_query_avx512(query) },
        #[cfg(not(target_arch = "x86_64"))]
        _ => unreachable!("x86 instruction sets are never available elsewhere"),
    }
}

/// A single-ray query from a ray that may enter the tree to the answer: compiled by [`ray_query`]
/// with the structure's instruction set and walked with that set's node kernel (with AVX-512, the
/// fused one where it applies, see [`super::fused`]), so that its set-up (the node test's constants, the
/// leaves' state) is made in the same function as the walk instead of being handed over to it in
/// memory.
pub trait RayQuery {
    /// What the query returns.
    type Output;
    /// Whether the fused node test applies to the query's ray ([`super::fused::applies`]).
    fn fused(&self) -> bool;
    /// Runs the query with `kernel`. Implementations are `#[inline(always)]`, so that their body
    /// is compiled into the copy that calls them.
    ///
    /// # Safety
    /// As [`NodeKernel::children`]: compiled with the kernel's target features, run on a processor
    /// that has them.
    unsafe fn run<K: NodeKernel>(self, kernel: K) -> Self::Output;
}

/// Runs `query` compiled for `isa`, which the processor must have (see the module documentation).
#[inline(always)]
pub fn ray_query<Q: RayQuery>(isa: Isa, query: Q) -> Q::Output {
    debug_assert!(isa.is_available());
    match isa {
        Isa::Portable => portable::ray_query(query),
        // SAFETY: the structure's instruction set is one the processor has (module documentation).
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { x86::ray_query_avx2(query) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 if query.fused() => unsafe { x86::ray_query_avx512(x86::FUSED, query) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { x86::ray_query_avx512(x86::Avx512, query) },
        #[cfg(not(target_arch = "x86_64"))]
        _ => unreachable!("x86 instruction sets are never available elsewhere"),
    }
}

/// The portable copies, compiled apart like the others rather than inlined into every caller:
/// inlined, their code and stack would weigh on the caller's registers and frame on machines that
/// run another copy.
mod portable {
    use super::*;

    #[inline(never)]
    pub fn ray_query<Q: RayQuery>(query: Q) -> Q::Output {
        // SAFETY: the portable kernel needs nothing beyond the target's baseline.
        unsafe { query.run(Portable) }
    }

    #[inline(never)]
    pub fn closest<C: Counters, L: Leaves<C>>(
        nodes: &[WideNode],
        depth: u32,
        start: u32,
        ray: &NodeRay,
        leaves: &mut L,
        counters: &mut C,
    ) {
        // SAFETY: the portable kernel needs nothing beyond the target's baseline.
        unsafe { traverse::closest(Portable, nodes, depth, start, ray, leaves, counters) }
    }

    #[inline(never)]
    pub fn any<C: Counters, L: Leaves<C>>(
        nodes: &[WideNode],
        depth: u32,
        start: u32,
        ray: &NodeRay,
        limit: f32,
        leaves: &mut L,
        counters: &mut C,
    ) -> bool {
        // SAFETY: as above.
        unsafe { traverse::any(Portable, nodes, depth, start, ray, limit, leaves, counters) }
    }

    #[inline(never)]
    pub fn closest_packet<C: Counters, L: PacketLeaves<C>>(
        nodes: &[WideNode],
        rays: &PacketRays,
        active: u32,
        leaves: &mut L,
        counters: &mut C,
    ) {
        // SAFETY: as above.
        unsafe { packet::closest(ScalarPacket, nodes, rays, active, leaves, counters) }
    }

    #[inline(never)]
    pub fn any_packet<C: Counters, L: PacketLeaves<C>>(
        nodes: &[WideNode],
        rays: &PacketRays,
        active: u32,
        leaves: &mut L,
        counters: &mut C,
    ) -> u32 {
        // SAFETY: as above.
        unsafe { packet::any(ScalarPacket, nodes, rays, active, leaves, counters) }
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::super::fused::FusedPlanes;
    pub use super::super::kernels::Avx512;
    use super::super::kernels::{Avx2, Avx512Fused};
    use super::super::packet_kernels::{Avx2Packet, Avx512Packet};
    use super::super::packet_prep::{Avx2Lanes, Avx512Lanes};
    use super::*;

    /// The fused kernel as a walk takes it, its constants made at the walk's start
    /// ([`NodeKernel::for_ray`]).
    pub const FUSED: Avx512Fused = Avx512Fused(FusedPlanes::NONE);

    /// # Safety
    /// The processor has AVX2, FMA and the bit instructions that come with them (see `Isa`).
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    pub unsafe fn packet_query_avx2<Q: PacketQuery>(query: Q) -> Q::Output {
        // SAFETY: compiled with AVX2, which the caller guarantees.
        unsafe { query.run(Avx2Lanes) }
    }

    /// # Safety
    /// The processor has AVX-512 F, VL, BW and DQ (and AVX2).
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt,avx512f,avx512vl,avx512bw,avx512dq")]
    pub unsafe fn packet_query_avx512<Q: PacketQuery>(query: Q) -> Q::Output {
        // SAFETY: compiled with AVX-512, which the caller guarantees.
        unsafe { query.run(Avx512Lanes) }
    }

    /// # Safety
    /// The processor has AVX2, FMA and the bit instructions that come with them (see `Isa`).
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    pub unsafe fn ray_query_avx2<Q: RayQuery>(query: Q) -> Q::Output {
        // SAFETY: compiled with AVX2, which the caller guarantees.
        unsafe { query.run(Avx2) }
    }

    /// # Safety
    /// The processor has AVX-512 F, VL, BW and DQ (and AVX2); `kernel` is [`Avx512`], or
    /// [`FUSED`] for a query whose ray the fused node test applies to. (Generic, so that each
    /// kernel's walk is a function of its own, with its own registers.)
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt,avx512f,avx512vl,avx512bw,avx512dq")]
    pub unsafe fn ray_query_avx512<K: NodeKernel, Q: RayQuery>(kernel: K, query: Q) -> Q::Output {
        // SAFETY: compiled with AVX-512, which the caller guarantees.
        unsafe { query.run(kernel) }
    }

    /// # Safety
    /// The processor has AVX2, FMA and the bit instructions that come with them (see `Isa`).
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    pub unsafe fn closest_avx2<C: Counters, L: Leaves<C>>(
        nodes: &[WideNode],
        depth: u32,
        start: u32,
        ray: &NodeRay,
        leaves: &mut L,
        counters: &mut C,
    ) {
        // SAFETY: compiled with AVX2, which the caller guarantees.
        unsafe { traverse::closest(Avx2, nodes, depth, start, ray, leaves, counters) }
    }

    /// # Safety
    /// As [`ray_query_avx512`], `kernel` being [`FUSED`] only if the fused node test applies to
    /// `ray`.
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt,avx512f,avx512vl,avx512bw,avx512dq")]
    pub unsafe fn closest_avx512<K: NodeKernel, C: Counters, L: Leaves<C>>(
        kernel: K,
        nodes: &[WideNode],
        depth: u32,
        start: u32,
        ray: &NodeRay,
        leaves: &mut L,
        counters: &mut C,
    ) {
        // SAFETY: compiled with AVX-512, which the caller guarantees.
        unsafe { traverse::closest(kernel, nodes, depth, start, ray, leaves, counters) }
    }

    /// # Safety
    /// The processor has AVX2, FMA and the bit instructions that come with them (see `Isa`).
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    pub unsafe fn any_avx2<C: Counters, L: Leaves<C>>(
        nodes: &[WideNode],
        depth: u32,
        start: u32,
        ray: &NodeRay,
        limit: f32,
        leaves: &mut L,
        counters: &mut C,
    ) -> bool {
        // SAFETY: compiled with AVX2, which the caller guarantees.
        unsafe { traverse::any(Avx2, nodes, depth, start, ray, limit, leaves, counters) }
    }

    /// # Safety
    /// As [`closest_avx512`].
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt,avx512f,avx512vl,avx512bw,avx512dq")]
    #[allow(clippy::too_many_arguments)]
    pub unsafe fn any_avx512<K: NodeKernel, C: Counters, L: Leaves<C>>(
        kernel: K,
        nodes: &[WideNode],
        depth: u32,
        start: u32,
        ray: &NodeRay,
        limit: f32,
        leaves: &mut L,
        counters: &mut C,
    ) -> bool {
        // SAFETY: compiled with AVX-512, which the caller guarantees.
        unsafe { traverse::any(kernel, nodes, depth, start, ray, limit, leaves, counters) }
    }

    /// # Safety
    /// The processor has AVX2, FMA and the bit instructions that come with them (see `Isa`).
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    pub unsafe fn closest_packet_avx2<C: Counters, L: PacketLeaves<C>>(
        nodes: &[WideNode],
        rays: &PacketRays,
        active: u32,
        leaves: &mut L,
        counters: &mut C,
    ) {
        // SAFETY: compiled with AVX2, which the caller guarantees.
        unsafe { packet::closest(Avx2Packet, nodes, rays, active, leaves, counters) }
    }

    /// # Safety
    /// The processor has AVX-512 F, VL, BW and DQ (and AVX2).
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt,avx512f,avx512vl,avx512bw,avx512dq")]
    pub unsafe fn closest_packet_avx512<C: Counters, L: PacketLeaves<C>>(
        nodes: &[WideNode],
        rays: &PacketRays,
        active: u32,
        leaves: &mut L,
        counters: &mut C,
    ) {
        // SAFETY: compiled with AVX-512, which the caller guarantees.
        unsafe { packet::closest(Avx512Packet, nodes, rays, active, leaves, counters) }
    }

    /// # Safety
    /// The processor has AVX2, FMA and the bit instructions that come with them (see `Isa`).
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    pub unsafe fn any_packet_avx2<C: Counters, L: PacketLeaves<C>>(
        nodes: &[WideNode],
        rays: &PacketRays,
        active: u32,
        leaves: &mut L,
        counters: &mut C,
    ) -> u32 {
        // SAFETY: compiled with AVX2, which the caller guarantees.
        unsafe { packet::any(Avx2Packet, nodes, rays, active, leaves, counters) }
    }

    /// # Safety
    /// The processor has AVX-512 F, VL, BW and DQ (and AVX2).
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt,avx512f,avx512vl,avx512bw,avx512dq")]
    pub unsafe fn any_packet_avx512<C: Counters, L: PacketLeaves<C>>(
        nodes: &[WideNode],
        rays: &PacketRays,
        active: u32,
        leaves: &mut L,
        counters: &mut C,
    ) -> u32 {
        // SAFETY: compiled with AVX-512, which the caller guarantees.
        unsafe { packet::any(Avx512Packet, nodes, rays, active, leaves, counters) }
    }
}
