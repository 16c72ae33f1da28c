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

/// A skin's inverse bind matrices in an accessor of count 0 (glTF requires ≥ 1): the gltf
/// crate computed `count - 1` and overflowed; the precheck names the accessor instead.
#[test]
fn accessor_with_count_zero_is_named() {
    let p = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/regressions/gltf/gltf_accessor_count_zero.gltf"
    );
    let err = tkio::gltf::read_bytes(&std::fs::read(p).unwrap())
        .unwrap_err()
        .to_string();
    assert!(err.contains("accessor 4 has count 0"), "{err}");
}
