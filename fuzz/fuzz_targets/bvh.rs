//! BVH: any bytes give Ok or Err; a scene that reads samples without NaN (when short enough)
//! and its BVH export reads back.
#![no_main]

#[path = "../targets.rs"]
mod targets;

libfuzzer_sys::fuzz_target!(|data: &[u8]| targets::bvh(data));
