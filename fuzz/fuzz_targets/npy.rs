//! NPY: any bytes give Ok or Err; an array that reads writes back to the same bits.
#![no_main]

#[path = "../targets.rs"]
mod targets;

libfuzzer_sys::fuzz_target!(|data: &[u8]| targets::npy(data));
