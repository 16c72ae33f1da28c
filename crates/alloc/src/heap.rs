//! glibc's heap set up for a short job: medium buffers on transparent huge pages too.
//!
//! [`HugePageAlloc`](crate::HugePageAlloc) maps buffers of a megabyte or more itself; the
//! rest goes to glibc's `malloc`. Left at its defaults, glibc maps every block of 128 KiB or
//! more on its own and unmaps it when it is freed (a loaded file, an accessor, a thread's
//! scratch buffers), and it grows its heaps 132 KiB at a time, so a whole `toonkit smear
//! offsets` of the benchmark tube (issue #14) took ~1,300 faults of 4 KiB pages beyond the
//! program's own ~370 — at 2–4 µs each in a virtual machine, more system time than the motion
//! offsets take. [`configure_heap`] makes glibc keep such blocks in one heap, grown once by
//! [`HEAP_RESERVE`] that is advised `MADV_HUGEPAGE`, and never hand it back: ~600 faults.

use std::ffi::c_int;

use crate::THRESHOLD;

/// Address space the heap grows by at once (only touched pages cost memory).
pub const HEAP_RESERVE: usize = 64 << 20;

/// Free memory at the top of the heap that glibc keeps rather than returns (the process is
/// short; the next buffer reuses it).
const TRIM_THRESHOLD: usize = 512 << 20;

/// A block that forces the heap to grow past its start-up size (below [`THRESHOLD`], so it
/// comes from the heap once the mapping threshold is raised).
const PROBE: usize = 256 << 10;

/// Sets glibc's `malloc` up for a short job and maps the [`RESERVE`](crate::RESERVE) of
/// large buffers; call it first in `main` (it changes process-wide settings, so a library
/// must not).
///
/// * blocks below [`THRESHOLD`] come from the heap (`M_MMAP_THRESHOLD`; larger ones are
///   [`HugePageAlloc`](crate::HugePageAlloc)'s);
/// * one heap for every thread (`M_ARENA_MAX` 1): the other arenas would be fresh mappings
///   of 4 KiB pages; small blocks still come from each thread's cache without a lock;
/// * the heap grows by [`HEAP_RESERVE`] at once, which is advised `MADV_HUGEPAGE`, and is
///   not trimmed (`M_TOP_PAD`, `M_TRIM_THRESHOLD`);
/// * the heap's next blocks start at its first 2 MiB boundary (below it, where the program's
///   start-up blocks lie, a huge page cannot fit), so they lie on huge pages too, which
///   [`populate`](crate::populate) can fault in ahead of need.
///
/// Advice only: without transparent huge pages (or on another C library) the heap works as
/// before. Changes the heap only on Linux with glibc.
pub fn configure_heap() {
    #[cfg(target_env = "gnu")]
    // SAFETY: `mallopt` only changes allocator settings; the probe block is allocated and
    // freed here and never touched, nor is the filler; `madvise` gives advice on pages of the
    // heap that lie between the probe and the heap's end, which are mapped (`sbrk` reports
    // the end).
    unsafe {
        let as_int = |x: usize| c_int::try_from(x).unwrap_or(c_int::MAX);
        libc::mallopt(libc::M_MMAP_THRESHOLD, as_int(THRESHOLD));
        libc::mallopt(libc::M_ARENA_MAX, 1);
        libc::mallopt(libc::M_TRIM_THRESHOLD, as_int(TRIM_THRESHOLD));
        libc::mallopt(libc::M_TOP_PAD, as_int(HEAP_RESERVE));
        // Opaque to the optimizer, which may drop a block that is freed unused.
        let probe = std::hint::black_box(libc::malloc(PROBE));
        let end = libc::sbrk(0) as usize;
        let start = (probe as usize) & !(PAGE - 1);
        libc::free(probe);
        // The probe lies in the heap only when glibc could grow it with `brk`.
        if !probe.is_null() && end != usize::MAX && end > start && end - start <= 2 * HEAP_RESERVE {
            libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
            // The freed probe is the start of the heap's free top: a filler up to the boundary
            // (a block glibc itself maps no longer, as the threshold is raised for it) leaves
            // the boundary as the top's new start.
            let boundary = (probe as usize).next_multiple_of(crate::HUGE_PAGE);
            if boundary > probe as usize {
                libc::mallopt(libc::M_MMAP_THRESHOLD, as_int(2 * crate::HUGE_PAGE));
                std::hint::black_box(libc::malloc(boundary - probe as usize));
                libc::mallopt(libc::M_MMAP_THRESHOLD, as_int(THRESHOLD));
            }
            crate::reserve::set_up(boundary);
            return;
        }
    }
    crate::reserve::set_up(0);
}

/// Base page size the heap's addresses are aligned to for `madvise`.
#[cfg(target_env = "gnu")]
const PAGE: usize = 4096;
