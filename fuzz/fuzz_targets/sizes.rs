//! Option sizes against their budgets: never a panic, never an accepted size over its limit.
#![no_main]

#[path = "../targets.rs"]
mod targets;

libfuzzer_sys::fuzz_target!(|data: &[u8]| targets::sizes(data));
