//! Links the `toonkit` binary as a position-dependent executable on Linux with glibc.
//!
//! Why: a PIE `toonkit` carries ~30,800 relative relocations (clap's command tree, vtables,
//! string tables) that the dynamic loader applies at every start, writing ~140 pages of
//! `.data.rel.ro` and `.got` (each a copy-on-write fault); linked at a fixed address they are
//! resolved by the linker. `toonkit --version` went from 1.4 to 1.2 ms (min of 200, hyperfine,
//! benchmark VM; issue #14). The cost: the executable's own image is no longer
//! address-randomized (shared libraries, heap and stack still are).

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let var = |k: &str| std::env::var(k).unwrap_or_default();
    if var("CARGO_CFG_TARGET_OS") == "linux" && var("CARGO_CFG_TARGET_ENV") == "gnu" {
        println!("cargo:rustc-link-arg-bin=toonkit=-no-pie");
    }
}
