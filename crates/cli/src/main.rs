//! The `toonkit` binary: everything is in the library ([`toonkit_cli::main`]).

/// Large buffers on transparent huge pages (see [`toonkit_alloc`]); only the binary sets this,
/// the libraries (and the Python module) keep their host's allocator.
#[cfg(target_os = "linux")]
#[global_allocator]
static ALLOCATOR: toonkit_alloc::HugePageAlloc = toonkit_alloc::HugePageAlloc;

fn main() -> std::process::ExitCode {
    // glibc's heap for a short job (one heap on huge pages, kept), before any work.
    #[cfg(target_os = "linux")]
    toonkit_alloc::configure_heap();
    toonkit_cli::main()
}
