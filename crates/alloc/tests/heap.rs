//! [`toonkit_alloc::configure_heap`] on the main thread of a fresh process (its own harness:
//! the settings are process-wide, and the test harness's threads would already hold arenas
//! of their own).

// Reads the heap's end and allocates through libc directly: what the settings change.
#![allow(unsafe_code)]

#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn main() {
    // The program's own heap before any setting: where a block of the heap may start.
    // SAFETY: `sbrk(0)` only reads the current end of the heap.
    let heap_start = unsafe { libc::sbrk(0) } as usize;
    toonkit_alloc::configure_heap();
    // SAFETY: as above.
    let heap_end = unsafe { libc::sbrk(0) } as usize;
    assert!(
        heap_end >= heap_start + toonkit_alloc::HEAP_RESERVE,
        "the heap grew by its reserve at once: {heap_start:#x}..{heap_end:#x}"
    );
    let block = 512 << 10;
    // SAFETY: a plain allocation, freed below and never dereferenced.
    let p = unsafe { libc::malloc(block) } as usize;
    assert!(p != 0);
    // SAFETY: `p` came from `malloc` above.
    unsafe { libc::free(p as *mut libc::c_void) };
    // SAFETY: as above.
    let after_free = unsafe { libc::sbrk(0) } as usize;
    assert_eq!(
        after_free, heap_end,
        "freed memory stays in the heap for the next block"
    );

    // A thread started now allocates from the same heap (no arena of its own).
    // SAFETY: as above; the block is freed at once and only its address kept.
    let q = std::thread::spawn(move || unsafe {
        let q = libc::malloc(block);
        libc::free(q);
        q as usize
    })
    .join()
    .expect("thread");
    assert_eq!(
        mapping_of(q).0.as_deref(),
        Some("[heap]"),
        "a thread's block"
    );

    // The block's mapping: the program's heap, advised for transparent huge pages where the
    // kernel has them.
    let (name, flags) = mapping_of(p);
    assert_eq!(
        name.as_deref(),
        Some("[heap]"),
        "a 512 KiB block comes from the heap, not a mapping of its own"
    );
    let flags = flags.expect("the heap's flags in /proc/self/smaps");
    let thp =
        std::fs::read_to_string("/sys/kernel/mm/transparent_hugepage/enabled").unwrap_or_default();
    if thp.is_empty() || thp.contains("[never]") {
        eprintln!("transparent huge pages are off here: advice not checked");
        return;
    }
    assert!(
        flags.split_whitespace().any(|f| f == "hg"),
        "the heap is advised MADV_HUGEPAGE (VmFlags:{flags})"
    );
    println!(
        "heap: {} MiB advised for huge pages",
        (heap_end - heap_start) >> 20
    );
    reserve(p, heap_start);
}

/// The heap's next blocks lie past its first huge-page boundary; large buffers are carved
/// from the reserve one after the other, zeroed; [`toonkit_alloc::populate`] makes a buffer
/// that nobody touched resident; a spent reserve falls back to mappings of their own.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn reserve(heap_block: usize, heap_start: usize) {
    use std::alloc::{GlobalAlloc, Layout};
    const HUGE: usize = 2 << 20;
    // The filler moved the heap's free top to a boundary: the next block starts there (past
    // its chunk header).
    assert!(
        heap_block % HUGE < 4096 && heap_block > heap_start.saturating_sub(HUGE),
        "a heap block at a 2 MiB boundary: {heap_block:#x} (heap from {heap_start:#x})"
    );
    let a = toonkit_alloc::HugePageAlloc;
    let layout = Layout::from_size_align(3 * HUGE + 5, 64).expect("layout");
    // SAFETY: valid non-zero layouts; reads and writes stay inside each block, and every
    // block is released with its own layout.
    unsafe {
        let first = a.alloc_zeroed(layout);
        let second = a.alloc_zeroed(layout);
        assert!(!first.is_null() && !second.is_null());
        assert_eq!(
            second as usize,
            first as usize + 4 * HUGE,
            "consecutive buffers of the reserve"
        );
        assert_eq!(mapping_of(first as usize).0.as_deref(), Some(""));
        toonkit_alloc::populate();
        if !populate_supported() {
            eprintln!("MADV_POPULATE_WRITE is missing here (Linux < 5.14): populate not checked");
            return;
        }
        let pages = layout.size().div_ceil(4096);
        let mut resident = vec![0u8; pages];
        let rc = libc::mincore(first.cast(), layout.size(), resident.as_mut_ptr());
        assert_eq!(rc, 0, "mincore");
        assert!(
            resident.iter().all(|r| r & 1 == 1),
            "populate made the untouched buffer resident"
        );
        assert!((0..layout.size())
            .step_by(4096)
            .all(|i| *second.add(i) == 0));
        *first = 1;
        *second.add(layout.size() - 1) = 2;
        // More than the reserve has left: a mapping of its own, aligned and zeroed too.
        let big = Layout::from_size_align(toonkit_alloc::RESERVE, 64).expect("layout");
        let third = a.alloc_zeroed(big);
        assert!(!third.is_null() && (third as usize).is_multiple_of(HUGE));
        assert!(
            !(first as usize..first as usize + toonkit_alloc::RESERVE).contains(&(third as usize))
        );
        assert!((0..big.size()).step_by(4096).all(|i| *third.add(i) == 0));
        assert_eq!((*first, *second.add(layout.size() - 1)), (1, 2));
        for (p, l) in [(first, layout), (second, layout), (third, big)] {
            a.dealloc(p, l);
        }
        // A released piece keeps its addresses (inaccessible): no later mapping lands where
        // `populate` may still be at work.
        assert!(
            mapping_of(first as usize).0.is_some(),
            "the piece stays reserved"
        );
        assert!(
            mapping_of(third as usize).0.is_none(),
            "a mapping of its own is unmapped"
        );
    }
    println!("reserve: buffers carved in order and populated ahead of use");
}

/// Whether the kernel knows `MADV_POPULATE_WRITE` (Linux 5.14), tried on a page of its own.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn populate_supported() -> bool {
    // SAFETY: a fresh private page, advised, then unmapped; nothing else refers to it.
    unsafe {
        let flags = libc::MAP_PRIVATE | libc::MAP_ANONYMOUS;
        let rw = libc::PROT_READ | libc::PROT_WRITE;
        let page = libc::mmap(std::ptr::null_mut(), 4096, rw, flags, -1, 0);
        assert!(page != libc::MAP_FAILED, "mmap");
        let ok = libc::madvise(page, 4096, libc::MADV_POPULATE_WRITE) == 0;
        libc::munmap(page, 4096);
        ok
    }
}

/// Name and `VmFlags` of the mapping holding `address`, from `/proc/self/smaps`.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn mapping_of(address: usize) -> (Option<String>, Option<String>) {
    let smaps = std::fs::read_to_string("/proc/self/smaps").expect("/proc/self/smaps");
    let (mut name, mut flags) = (None, None);
    let mut inside = false;
    for line in smaps.lines() {
        let mut words = line.split_whitespace();
        if let Some((a, b)) = words.next().and_then(|r| r.split_once('-')) {
            if let (Ok(a), Ok(b)) = (usize::from_str_radix(a, 16), usize::from_str_radix(b, 16)) {
                inside = (a..b).contains(&address);
                if inside {
                    name = Some(words.nth(4).unwrap_or("").to_string());
                }
                continue;
            }
        }
        if inside {
            if let Some(f) = line.strip_prefix("VmFlags:") {
                flags = Some(f.to_string());
                break;
            }
        }
    }
    (name, flags)
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn main() {}
