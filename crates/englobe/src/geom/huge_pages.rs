//! Huge pages for the large arrays that queries read at random: a structure's nodes and triangle
//! blocks.
//!
//! A ray that is not coherent with the previous one reads a handful of nodes and blocks scattered
//! over the whole structure, and on ordinary 4 KiB pages nearly each of them needs its own
//! translation: past a few megabytes the processor's translation caches miss too, and each miss
//! walks the page tables before the load can start. Linux backs memory with 2 MiB pages when asked
//! (`madvise(MADV_HUGEPAGE)`, the transparent huge pages of most distributions' default
//! `madvise` mode), if asked before the memory is first written. Embree asks the same for the
//! blocks its builders allocate.

/// Arrays smaller than this are left as they are: they hold no whole huge page.
const HUGE_PAGE: usize = 2 << 20;

/// Asks that the `bytes` bytes from `start`, not yet written, be backed by huge pages when they
/// are. A hint: nothing on other systems, or if the kernel refuses; the memory is the same.
pub fn advise(start: *const u8, bytes: usize) {
    #[cfg(target_os = "linux")]
    if bytes >= HUGE_PAGE {
        // The advice applies to whole pages: the ones inside the range (4 KiB on x86-64, 16 or
        // 64 KiB on some ARM systems).
        // SAFETY: `sysconf` only reads a system setting.
        let Ok(page) = usize::try_from(unsafe { libc::sysconf(libc::_SC_PAGESIZE) }) else { return };
        if page == 0 {
            return;
        }
        let first = (start as usize).next_multiple_of(page);
        let end = (start as usize + bytes) / page * page;
        if end > first {
            // SAFETY: `madvise` with `MADV_HUGEPAGE` changes how the pages of a mapping the
            // caller owns are backed, never their contents or whether they can be read; the
            // range lies inside the caller's allocation. An error leaves the pages as they were.
            unsafe { libc::madvise(first as *mut libc::c_void, end - first, libc::MADV_HUGEPAGE) };
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = (start, bytes);
}

/// [`advise`] for the whole allocation of `values`, its capacity, before it is filled.
pub fn advise_vec<T>(values: &Vec<T>) {
    advise(values.as_ptr() as *const u8, values.capacity() * size_of::<T>());
}
