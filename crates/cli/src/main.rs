//! The `toonkit` binary: everything is in the library ([`toonkit_cli::main`]).

fn main() -> std::process::ExitCode {
    toonkit_cli::main()
}
