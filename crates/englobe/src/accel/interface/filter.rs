//! Hit filters: a caller's test that can reject a candidate hit during a query (a cut-out
//! texture's transparent texels, the surface a ray starts from, objects a ray should not see),
//! Embree's intersection and occlusion filter functions (`rtcSetGeometryIntersectFilterFunction`)
//! as a generic parameter.
//!
//! A query generic over [`HitFilter`] is compiled once per filter type: with [`NoFilter`] the
//! filter's calls vanish and the query is the unfiltered one, instruction for instruction where
//! [`HitFilter::ACCEPTS_ALL`] lets it skip work (an occlusion query stops at the first block hit
//! without looking at which lane). Any closure `FnMut(&H) -> bool` is a filter.
//!
//! What a filter sees: for closest-hit queries, each candidate that would become the closest hit
//! so far (a rejected one is forgotten and the query goes on as if the primitive were not hit);
//! for any-hit queries, each hit found until one is accepted. A primitive is offered its nearest
//! hit in the ray's interval only: rejecting a sphere's entry does not offer its exit.

/// A caller's test of candidate hits of type `H`: true keeps the hit.
pub trait HitFilter<H> {
    /// True only for a filter that accepts every hit ([`NoFilter`]): queries may then skip it.
    const ACCEPTS_ALL: bool = false;

    /// Whether to keep `hit`.
    fn accept(&mut self, hit: &H) -> bool;
}

/// The absent filter: every hit is kept, at no cost.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NoFilter;

impl<H> HitFilter<H> for NoFilter {
    const ACCEPTS_ALL: bool = true;

    #[inline(always)]
    fn accept(&mut self, _hit: &H) -> bool {
        true
    }
}

impl<H, F: FnMut(&H) -> bool> HitFilter<H> for F {
    #[inline(always)]
    fn accept(&mut self, hit: &H) -> bool {
        self(hit)
    }
}
