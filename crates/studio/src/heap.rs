//! How the server's process hands freed clips back to the system.
//!
//! glibc's allocator raises its mmap threshold each time a large block is freed, so after the
//! first clip is dropped every later clip-sized buffer comes from the heap, and freed heap
//! memory stays resident (per thread arena) instead of going back. A stopmo segmentation of the
//! face (the 155 MiB clip, its cut and its parts, freed and made on different threads) then
//! peaked at 645 MiB; with the threshold fixed, every buffer of 256 KiB or more is its own
//! mapping, returned when freed: 357 MiB (docs/studio-budgets.md).

/// Buffers of this many bytes or more get their own mapping.
pub const DEFAULT_MMAP_THRESHOLD: usize = 256 * 1024;

/// Fixes the allocator's mmap threshold at [`DEFAULT_MMAP_THRESHOLD`] (glibc; elsewhere the
/// system allocator returns large blocks by itself and this does nothing).
pub fn return_large_buffers() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: `mallopt` only sets an allocator parameter; it is called before the server's
    // threads start and takes plain integers.
    #[allow(unsafe_code)]
    unsafe {
        libc::mallopt(
            libc::M_MMAP_THRESHOLD,
            DEFAULT_MMAP_THRESHOLD as libc::c_int,
        );
    }
}
