//! STL: any bytes give Ok or Err; a mesh that reads writes back to the same welded mesh.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tkio::stl;

fuzz_target!(|data: &[u8]| {
    if let Ok(m) = stl::read(data) {
        let again = stl::read(&stl::write_binary(&m)).expect("re-read of written STL");
        assert_eq!(again.positions, m.positions);
        assert_eq!(again.triangles, m.triangles);
    }
});
