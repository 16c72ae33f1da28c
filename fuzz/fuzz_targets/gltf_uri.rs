//! glTF buffer URIs: the confinement rule (only paths inside the file's folder).
#![no_main]

#[path = "../targets.rs"]
mod targets;

libfuzzer_sys::fuzz_target!(|data: &[u8]| targets::gltf_uri(data));
