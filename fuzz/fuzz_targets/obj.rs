//! OBJ: any bytes give Ok or Err; a mesh that reads writes back to exactly the same mesh.
#![no_main]

#[path = "../targets.rs"]
mod targets;

libfuzzer_sys::fuzz_target!(|data: &[u8]| targets::obj(data));
