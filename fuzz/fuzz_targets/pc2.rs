//! PC2: any bytes give Ok or Err; a valid file re-encodes to the same positions.
#![no_main]

#[path = "../targets.rs"]
mod targets;

libfuzzer_sys::fuzz_target!(|data: &[u8]| targets::pc2(data));
