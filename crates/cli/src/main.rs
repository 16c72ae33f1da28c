//! The `toonkit` binary: everything is in the library ([`toonkit_cli::main`]).

/// Huge-page buffers, glibc's heap set up for short jobs: the binary only ([`toonkit_alloc`]).
#[cfg(target_os = "linux")]
#[global_allocator]
static ALLOCATOR: toonkit_alloc::HugePageAlloc = toonkit_alloc::HugePageAlloc;

fn main() -> std::process::ExitCode {
    #[cfg(target_os = "linux")]
    toonkit_alloc::configure_heap();
    toonkit_cli::main()
}
