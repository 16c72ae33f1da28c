//! NPY: any bytes give Ok or Err; an array that reads writes back to the same bits.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tkio::npy;

fuzz_target!(|data: &[u8]| {
    if let Ok((shape, values)) = npy::read_f32(data) {
        let bytes = npy::write_f32(&shape, &values).expect("write of a read array");
        let (shape2, values2) = npy::read_f32(&bytes).expect("re-read of written NPY");
        assert_eq!(shape, shape2);
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&values), bits(&values2));
    }
});
