//! Batches of queries: one answer per ray written into the caller's slice, rays split across
//! threads (rayon, with the `parallel` feature) when the batch is large enough to pay for it.
//! Nothing is allocated per ray: each ray's query is the single-ray query (its stack on the
//! call stack), and each thread writes a disjoint part of the output.

use crate::Ray;

/// Rays per batch below which a batch runs on the calling thread alone.
pub const PARALLEL_BATCH: usize = 1024;

/// Rays a thread takes at a time in a parallel batch.
const CHUNK: usize = 256;

/// A batch whose output slice is not as long as its ray slice.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("a batch of {rays} rays was given {outputs} places for its answers")]
pub struct BatchSizeMismatch {
    /// Rays given.
    pub rays: usize,
    /// Places given for the answers.
    pub outputs: usize,
}

/// Writes `query(&rays[i])` into `out[i]` for every ray, in parallel above [`PARALLEL_BATCH`]
/// rays when the `parallel` feature is on.
pub fn run_batch<T: Send>(
    rays: &[Ray],
    out: &mut [T],
    query: impl Fn(&Ray) -> T + Sync,
) -> Result<(), BatchSizeMismatch> {
    if rays.len() != out.len() {
        return Err(BatchSizeMismatch { rays: rays.len(), outputs: out.len() });
    }
    #[cfg(feature = "parallel")]
    if rays.len() >= PARALLEL_BATCH {
        use rayon::prelude::*;
        out.par_chunks_mut(CHUNK).zip(rays.par_chunks(CHUNK)).for_each(|(out, rays)| {
            for (o, r) in out.iter_mut().zip(rays) {
                *o = query(r);
            }
        });
        return Ok(());
    }
    let _ = CHUNK;
    for (o, r) in out.iter_mut().zip(rays) {
        *o = query(r);
    }
    Ok(())
}

/// Calls `query` on consecutive pieces of `rays` and `out`, `width` rays at a time (the last
/// piece perhaps shorter), in parallel above [`PARALLEL_BATCH`] rays when the `parallel` feature
/// is on: for queries that trace several rays together (packets).
pub fn run_batch_chunks<T: Send>(
    rays: &[Ray],
    out: &mut [T],
    width: usize,
    query: impl Fn(&[Ray], &mut [T]) + Sync,
) -> Result<(), BatchSizeMismatch> {
    if rays.len() != out.len() {
        return Err(BatchSizeMismatch { rays: rays.len(), outputs: out.len() });
    }
    // A thread's share is a whole number of pieces, so that no piece is cut in two.
    let share = CHUNK.div_ceil(width) * width;
    let run = |out: &mut [T], rays: &[Ray]| {
        for (o, r) in out.chunks_mut(width).zip(rays.chunks(width)) {
            query(r, o);
        }
    };
    #[cfg(feature = "parallel")]
    if rays.len() >= PARALLEL_BATCH {
        use rayon::prelude::*;
        out.par_chunks_mut(share).zip(rays.par_chunks(share)).for_each(|(out, rays)| run(out, rays));
        return Ok(());
    }
    let _ = share;
    run(out, rays);
    Ok(())
}

/// Calls `query` on consecutive pieces of `rays` and `out`, `width` rays at a time (the last
/// piece perhaps shorter), on the calling thread: the packet queries' loop.
pub fn run_packets<T>(
    rays: &[Ray],
    out: &mut [T],
    width: usize,
    mut query: impl FnMut(&[Ray], &mut [T]),
) -> Result<(), BatchSizeMismatch> {
    if rays.len() != out.len() {
        return Err(BatchSizeMismatch { rays: rays.len(), outputs: out.len() });
    }
    for (rays, out) in rays.chunks(width).zip(out.chunks_mut(width)) {
        query(rays, out);
    }
    Ok(())
}

/// [`run_batch_chunks`] by packets of `width` rays: each piece `coherent` accepts goes to
/// `packet` whole, the others ray by ray to `single`.
pub fn run_batch_packets<T: Send>(
    rays: &[Ray],
    out: &mut [T],
    width: usize,
    coherent: impl Fn(&[Ray]) -> bool + Sync,
    packet: impl Fn(&[Ray], &mut [T]) + Sync,
    single: impl Fn(&Ray) -> T + Sync,
) -> Result<(), BatchSizeMismatch> {
    run_batch_chunks(rays, out, width, |rays, out| {
        if coherent(rays) {
            packet(rays, out);
        } else {
            for (o, r) in out.iter_mut().zip(rays) {
                *o = single(r);
            }
        }
    })
}
