//! glTF/GLB from bytes: any bytes give Ok or Err.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = tkio::gltf::read_bytes(data);
});
