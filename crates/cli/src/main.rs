//! The `toonkit` binary: everything is in the library ([`toonkit_cli::main`]).

#[cfg(target_os = "linux")]
mod huge_pages;

/// Large buffers on transparent huge pages (see [`huge_pages`]); only the binary sets this,
/// the libraries (and the Python module) keep their host's allocator.
#[cfg(target_os = "linux")]
#[global_allocator]
static ALLOCATOR: huge_pages::HugePageAlloc = huge_pages::HugePageAlloc;

fn main() -> std::process::ExitCode {
    toonkit_cli::main()
}
