//! Helpers shared by the loa integration tests: asset paths and example keystrokes.
#![allow(dead_code)]

use std::path::PathBuf;

use loa::Keystrokes;

/// Path of a shared test asset; panics (fails loudly) if it is missing.
pub(crate) fn data(rel: &str) -> PathBuf {
    let p = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/")).join(rel);
    assert!(p.exists(), "missing test asset {}", p.display());
    p
}

/// An example keystroke file of `examples/loa/`.
pub(crate) fn example(name: &str) -> Keystrokes {
    let p = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/loa/")).join(name);
    let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    Keystrokes::parse(&text).unwrap()
}

/// `keys` with every keystroke's stiffness and/or damping replaced.
pub(crate) fn with_params(
    keys: &Keystrokes,
    stiffness: Option<f64>,
    damping: Option<f64>,
) -> Keystrokes {
    let ks = keys
        .keys()
        .iter()
        .cloned()
        .map(|mut k| {
            k.stiffness = stiffness.unwrap_or(k.stiffness);
            k.damping = damping.unwrap_or(k.damping);
            k
        })
        .collect();
    Keystrokes::new(ks, keys.fps()).unwrap()
}

/// The character of a test asset (skinned glTF or BVH) in `pose` at 24 fps.
pub(crate) fn character(rel: &str, pose: &str) -> (anim::Scene, loa::animate::Character) {
    let path = data(rel);
    let scene = match tkio::load(
        &path,
        &tkio::LoadOptions {
            fps: 24.0,
            ..Default::default()
        },
    )
    .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
    {
        tkio::Loaded::Scene(s) => *s,
        _ => panic!("{}: not a scene", path.display()),
    };
    let pose = pose.parse().unwrap();
    let character = loa::animate::Character::from_scene(&scene, &pose, 24.0).unwrap();
    (scene, character)
}

/// Largest per-frame motion of any chain point over the line's length.
pub(crate) fn max_jump(a: &loa::Animation) -> f64 {
    a.frames
        .windows(2)
        .map(|w| {
            let length = w[0].chain.total_length().max(w[1].chain.total_length());
            let (p, q) = (w[0].chain.joints(), w[1].chain.joints());
            p.iter()
                .zip(&q)
                .map(|(a, b)| (*a - *b).length())
                .fold(0.0, f64::max)
                / length
        })
        .fold(0.0, f64::max)
}
