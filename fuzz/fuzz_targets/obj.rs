//! OBJ: any bytes give Ok or Err; a mesh that reads writes back to exactly the same mesh.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tkio::obj;

fuzz_target!(|data: &[u8]| {
    if let Ok(m) = obj::read(data) {
        let again = obj::read(obj::write(&m).as_bytes()).expect("re-read of written OBJ");
        assert_eq!(again, m);
    }
});
