//! MDD: any bytes give Ok or Err; a valid file re-encodes to the same positions.
#![no_main]

use anim::glam::Vec3;
use anim::Mesh;
use libfuzzer_sys::fuzz_target;
use tkio::mdd;

fuzz_target!(|data: &[u8]| {
    let points = mdd::read_header(data)
        .map(|h| h.points)
        .unwrap_or(3)
        .min(1 << 16);
    let rest = Mesh::new("r", vec![Vec3::ZERO; points], Vec::new());
    if let Ok(a) = mdd::read(data, rest.clone(), 24.0) {
        let b = mdd::read(&mdd::write(&a), rest, a.fps).expect("re-read of written MDD");
        assert_eq!(a.positions(), b.positions());
    }
});
