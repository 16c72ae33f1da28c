//! STL: any bytes give Ok or Err; a mesh that reads writes back to the same welded mesh.
#![no_main]

#[path = "../targets.rs"]
mod targets;

libfuzzer_sys::fuzz_target!(|data: &[u8]| targets::stl(data));
