//! The `toonkit` binary: everything is in the library ([`toonkit_cli::main`]).

/// Large buffers on transparent huge pages (see [`toonkit_alloc`]); only the binary sets this,
/// the libraries (and the Python module) keep their host's allocator.
#[cfg(target_os = "linux")]
#[global_allocator]
static ALLOCATOR: toonkit_alloc::HugePageAlloc = toonkit_alloc::HugePageAlloc;

fn main() -> std::process::ExitCode {
    toonkit_cli::main()
}
