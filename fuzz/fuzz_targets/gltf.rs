//! glTF/GLB from bytes: any bytes give Ok or Err.
#![no_main]

#[path = "../targets.rs"]
mod targets;

libfuzzer_sys::fuzz_target!(|data: &[u8]| targets::gltf(data));
