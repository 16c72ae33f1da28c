//! Regression inputs found by fuzzing: each must be an error, never a panic.

#[test]
fn fuzz_regressions_are_errors() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fuzz/regressions/gltf");
    let mut n = 0;
    for e in std::fs::read_dir(dir).expect("fuzz/regressions exists") {
        let p = e.unwrap().path();
        let bytes = std::fs::read(&p).unwrap();
        assert!(
            tkio::gltf::read_bytes(&bytes).is_err(),
            "{} was accepted",
            p.display()
        );
        n += 1;
    }
    assert!(n >= 1, "no regression file found in {dir}");
}
