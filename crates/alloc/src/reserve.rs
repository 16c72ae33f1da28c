//! Huge pages zeroed ahead of need: a reserve the large buffers are carved from, faulted in
//! (with the start of the heap) by a thread that is idle while the job starts.
//!
//! The kernel zeroes every huge page on the thread that first touches it: 2 MiB at a time,
//! ~0.2 ms each on the benchmark VM. A whole `smear offsets` of the benchmark tube (issue
//! #14) touches nine, much of it on its critical path (the file read into the heap, the rig
//! built before the ribbons, the skinning's output). [`populate`] has the kernel fault those
//! pages in on another thread (`MADV_POPULATE_WRITE`: page tables only, no byte written, so
//! it cannot race with what the owning thread writes) while the main thread parses, reads
//! and decodes — time in which a second core has nothing to do.

use std::ptr;
use std::sync::atomic::{AtomicUsize, Ordering};

use crate::HUGE_PAGE;

/// Address space of the reserve that buffers of [`THRESHOLD`](crate::THRESHOLD) bytes or
/// more are carved from, each once and in order (then they get mappings of their own).
/// Untouched address space costs no memory; [`populate`] makes all of it resident.
pub const RESERVE: usize = 16 << 20;

/// How much of the heap, from its first huge-page boundary, [`populate`] faults in.
pub const HEAP_POPULATE: usize = 6 << 20;

/// Start of the reserve (2 MiB-aligned), 0 when there is none.
static BASE: AtomicUsize = AtomicUsize::new(0);
/// Bytes of the reserve handed out.
static TAKEN: AtomicUsize = AtomicUsize::new(0);
/// First huge-page boundary of the heap, 0 when the heap was not set up.
static HEAP: AtomicUsize = AtomicUsize::new(0);

/// Maps the reserve (advised for huge pages; nothing touched) and records where the heap's
/// huge pages start (0: unknown). Called once, by [`configure_heap`](crate::configure_heap).
pub(crate) fn set_up(heap: usize) {
    HEAP.store(heap, Ordering::Release);
    if BASE.load(Ordering::Acquire) != 0 {
        return;
    }
    let p = crate::map(RESERVE);
    if !p.is_null() {
        BASE.store(p as usize, Ordering::Release);
    }
}

/// `len` bytes (whole huge pages) of the reserve that were never handed out, hence zero, or
/// null when there is no reserve or not enough of it is left.
pub(crate) fn take(len: usize) -> *mut u8 {
    let base = BASE.load(Ordering::Acquire);
    if base == 0 {
        return ptr::null_mut();
    }
    let mut taken = TAKEN.load(Ordering::Relaxed);
    loop {
        let Some(end) = taken.checked_add(len).filter(|&end| end <= RESERVE) else {
            return ptr::null_mut();
        };
        match TAKEN.compare_exchange_weak(taken, end, Ordering::Relaxed, Ordering::Relaxed) {
            Ok(_) => return (base + taken) as *mut u8,
            Err(now) => taken = now,
        }
    }
}

/// Whether `address` lies in the reserve.
pub(crate) fn owns(address: usize) -> bool {
    let base = BASE.load(Ordering::Acquire);
    base != 0 && (base..base + RESERVE).contains(&address)
}

/// Faults in the first [`HEAP_POPULATE`] bytes of the heap, then the whole reserve, a huge
/// page at a time; does nothing before [`configure_heap`](crate::configure_heap).
///
/// Run it on a thread that would otherwise wait while the job starts (the `toonkit` binary
/// hands it to its second worker): the pages are zeroed there instead of on the thread that
/// first writes them. Buffers already released are skipped (their range stays reserved,
/// inaccessible, and the kernel refuses it); pages already in place are left as they are.
/// Before Linux 5.14 (no `MADV_POPULATE_WRITE`) it changes nothing.
///
/// Does nothing where transparent huge pages are off: faulting in megabytes 4 KiB at a time
/// would keep that thread from the job's first parallel loops, for pages the job may never
/// use.
///
/// # Performance
/// ~0.2 ms per huge page on the benchmark VM, 11 in all.
pub fn populate() {
    let mode = std::fs::read_to_string("/sys/kernel/mm/transparent_hugepage/enabled");
    if !mode.is_ok_and(|m| m.contains("[always]") || m.contains("[madvise]")) {
        return;
    }
    let heap = HEAP.load(Ordering::Acquire);
    let base = BASE.load(Ordering::Acquire);
    for (start, len) in [(heap, HEAP_POPULATE), (base, RESERVE)] {
        if start == 0 {
            continue;
        }
        for at in (start..start + len).step_by(HUGE_PAGE) {
            // SAFETY: populating maps zero pages where none are mapped and writes no byte, so
            // whatever other threads store meanwhile is untouched; an unmapped range fails.
            unsafe {
                libc::madvise(
                    at as *mut libc::c_void,
                    HUGE_PAGE,
                    libc::MADV_POPULATE_WRITE,
                );
            }
        }
    }
}
