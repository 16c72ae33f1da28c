//! The `toonkit` binary's global allocator: large buffers on transparent huge pages (Linux).
//!
//! A whole `toonkit` job touches tens of megabytes of fresh memory (a sampled clip's
//! positions, the motion offsets, the encoded output): with 4 KiB pages that is thousands of
//! page faults, each costing microseconds (more in a VM), which dominated the whole-process
//! time of `toonkit smear offsets` (issue #14: 6,200 faults, ~40 % of the run). Buffers of
//! at least [`THRESHOLD`] bytes are mapped on their own, 2 MiB-aligned, and advised
//! `MADV_HUGEPAGE`, so the kernel backs them with 2 MiB pages where it can (systems with
//! transparent huge pages in `madvise` or `always` mode); everything smaller goes to the
//! system allocator. Without huge pages the mapping still works, with 4 KiB pages.
//! [`configure_heap`], called first in `main`, does the same for glibc's heap, where every
//! smaller block lives (one heap for all threads, grown once and advised; the benchmark
//! tube's `smear offsets`: 1,810 → ~600 faults, ~2 ms of the whole process).
//!
//! glibc's `glibc.malloc.hugetlb=1` tunable does the same, but only through an environment
//! variable read before `main`; this does it for every run of the binary. mimalloc (with or
//! without its large-OS-page option) was measured against it on the benchmark tube (issue
//! #14): as fast for `smear offsets`, slower for `convert` (more system time), so this stays.
//!
//! Large buffers are first carved from a [`RESERVE`] mapped at start-up, which [`populate`]
//! faults in on an idle thread (with the heap's first megabytes) while the job starts: the
//! kernel's zeroing of those pages moves off the critical path (issue #14: with the heap's
//! blocks moved onto huge pages, ~1.3 ms of the tube's ~13).
//!
//! Its own crate, apart from the CLI and the libraries: only the binary installs it (the
//! libraries and the Python module keep their host's allocator), and it is the one place of
//! the workspace that needs `unsafe`.
//!
//! ```no_run
//! #[cfg(target_os = "linux")]
//! #[global_allocator]
//! static ALLOCATOR: toonkit_alloc::HugePageAlloc = toonkit_alloc::HugePageAlloc;
//!
//! fn main() {
//!     #[cfg(target_os = "linux")]
//!     toonkit_alloc::configure_heap();
//!     // … the program
//! }
//! ```

#![cfg(target_os = "linux")]
// The allocator interface itself is unsafe; this is the one crate of the workspace that needs it.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::ptr;

mod heap;
mod reserve;

pub use heap::{configure_heap, HEAP_RESERVE};
pub use reserve::{populate, HEAP_POPULATE, RESERVE};

/// Size of a transparent huge page on x86-64 and aarch64 Linux (with 4 KiB base pages).
const HUGE_PAGE: usize = 2 << 20;

/// Smallest allocation that gets its own huge-page mapping: below it, the rounding up to whole
/// huge pages would waste more than it saves.
pub const THRESHOLD: usize = 1 << 20;

/// [`System`] for small allocations; 2 MiB-aligned anonymous mappings advised
/// `MADV_HUGEPAGE` for those of [`THRESHOLD`] bytes or more.
#[derive(Debug, Clone, Copy)]
pub struct HugePageAlloc;

/// Whether a layout gets its own mapping (the same answer at allocation and release, as
/// `GlobalAlloc` hands back the same layout).
fn mapped(size: usize, align: usize) -> bool {
    size >= THRESHOLD && align <= HUGE_PAGE
}

/// `size` rounded up to whole huge pages.
fn mapping_len(size: usize) -> usize {
    size.div_ceil(HUGE_PAGE) * HUGE_PAGE
}

/// `size` bytes (zeroed: a fresh anonymous mapping, or reserve never handed out before) at a
/// 2 MiB boundary, or null.
fn map(size: usize) -> *mut u8 {
    let len = mapping_len(size);
    let p = reserve::take(len);
    if !p.is_null() {
        return p;
    }
    let Some(reserve) = len.checked_add(HUGE_PAGE) else {
        return ptr::null_mut();
    };
    // SAFETY: an anonymous private mapping at an address the kernel chooses; no existing
    // memory is affected.
    let base = unsafe {
        libc::mmap(
            ptr::null_mut(),
            reserve,
            libc::PROT_READ | libc::PROT_WRITE,
            libc::MAP_PRIVATE | libc::MAP_ANONYMOUS,
            -1,
            0,
        )
    };
    if base == libc::MAP_FAILED {
        return ptr::null_mut();
    }
    let base = base as usize;
    let start = base.next_multiple_of(HUGE_PAGE);
    // SAFETY: both ranges lie inside the mapping just made and outside [start, start + len).
    unsafe {
        if start > base {
            libc::munmap(base as *mut libc::c_void, start - base);
        }
        let tail = base + reserve - (start + len);
        if tail > 0 {
            libc::munmap((start + len) as *mut libc::c_void, tail);
        }
        // Advice only: without transparent huge pages this fails and 4 KiB pages are used.
        libc::madvise(start as *mut libc::c_void, len, libc::MADV_HUGEPAGE);
    }
    start as *mut u8
}

/// Gives back a block of [`map`]: its pages are freed. A piece of the reserve keeps its address
/// range (inaccessible), so that no later mapping lands where [`populate`] may still reach.
///
/// # Safety
/// `ptr` and `len` are a block of [`map`] that nothing uses any more.
unsafe fn release(ptr: *mut u8, len: usize) {
    let ptr = ptr as *mut libc::c_void;
    // SAFETY: the range is the caller's block, whole huge pages, used by nothing else.
    unsafe {
        if reserve::owns(ptr as usize)
            && libc::mmap(
                ptr,
                len,
                libc::PROT_NONE,
                libc::MAP_PRIVATE | libc::MAP_ANONYMOUS | libc::MAP_FIXED | libc::MAP_NORESERVE,
                -1,
                0,
            ) != libc::MAP_FAILED
        {
            return;
        }
        libc::munmap(ptr, len);
    }
}

// SAFETY: small layouts are forwarded to `System` unchanged; large ones get a fresh mapping or
// a never-used piece of the reserve, of at least `size` bytes aligned to 2 MiB (≥ their
// alignment), that only `dealloc` releases, with the same layout, hence the same length.
unsafe impl GlobalAlloc for HugePageAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if mapped(layout.size(), layout.align()) {
            map(layout.size())
        } else {
            // SAFETY: the caller's layout contract is passed on.
            unsafe { System.alloc(layout) }
        }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if mapped(layout.size(), layout.align()) {
            // Fresh mappings and never-used reserve are zero: no page is touched here.
            map(layout.size())
        } else {
            // SAFETY: as `alloc`.
            unsafe { System.alloc_zeroed(layout) }
        }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        if mapped(layout.size(), layout.align()) {
            // SAFETY: `ptr` came from `map` with this size (the caller's contract): a piece
            // of the reserve or a mapping of its own, either way no other block's memory.
            unsafe { release(ptr, mapping_len(layout.size())) }
        } else {
            // SAFETY: `ptr` came from `System` with this layout.
            unsafe { System.dealloc(ptr, layout) }
        }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let align = layout.align();
        if !mapped(layout.size(), align) && !mapped(new_size, align) {
            // SAFETY: both layouts belong to `System`.
            return unsafe { System.realloc(ptr, layout, new_size) };
        }
        if mapped(layout.size(), align)
            && mapped(new_size, align)
            && mapping_len(new_size) == mapping_len(layout.size())
        {
            // Still fits the mapping it has.
            return ptr;
        }
        // SAFETY: `new_size` with the old alignment is a valid layout (the caller's contract).
        let new_layout = unsafe { Layout::from_size_align_unchecked(new_size, align) };
        // SAFETY: as `alloc`; then both blocks are valid for the smaller of the two sizes and
        // do not overlap (the new one is fresh), and the old one is released with its layout.
        unsafe {
            let new = self.alloc(new_layout);
            if !new.is_null() {
                ptr::copy_nonoverlapping(ptr, new, layout.size().min(new_size));
                self.dealloc(ptr, layout);
            }
            new
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn large_buffers_are_aligned_zeroed_and_survive_growth_and_shrinking() {
        let a = HugePageAlloc;
        let layout = Layout::from_size_align(THRESHOLD + 5, 16).unwrap();
        // SAFETY: a valid non-zero layout; every access stays inside the block's size.
        unsafe {
            let p = a.alloc_zeroed(layout);
            assert!(!p.is_null());
            assert_eq!(p as usize % HUGE_PAGE, 0);
            assert!((0..layout.size()).step_by(4096).all(|i| *p.add(i) == 0));
            *p = 7;
            *p.add(layout.size() - 1) = 9;
            let q = a.realloc(p, layout, 3 * THRESHOLD);
            assert_eq!((*q, *q.add(layout.size() - 1)), (7, 9));
            let grown = Layout::from_size_align(3 * THRESHOLD, 16).unwrap();
            let r = a.realloc(q, grown, 100);
            assert_eq!(*r, 7);
            a.dealloc(r, Layout::from_size_align(100, 16).unwrap());
        }
    }
}
