//! Software prefetches: hints that start loading memory into the cache before it is read, so
//! that independent misses overlap instead of following one another.

/// Starts loading `items[index]` into the cache: every 64-byte line of its size past its start
/// (a node's four, a triangle block's three). Any index is allowed: out of bounds, it loads
/// nothing useful and does no harm.
#[inline(always)]
pub fn prefetch<T>(items: &[T], index: u32) {
    #[cfg(target_arch = "x86_64")]
    {
        // No bounds check: a prefetch is a hint that never faults, whatever the address, and a
        // wrapping offset is defined for any index.
        let p = items.as_ptr().wrapping_add(index as usize) as *const i8;
        // SAFETY: prefetching never dereferences: it neither faults nor reads into the program.
        unsafe {
            use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
            for line in 0..std::mem::size_of::<T>().div_ceil(64) {
                _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(64 * line));
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (items, index);
}
