//! Property tests: arbitrary bytes, and real files with random byte edits, never make a reader
//! panic (they return `Ok` or `Err`).

use std::path::PathBuf;
use std::sync::OnceLock;

use anim::glam::Vec3;
use anim::{Mesh, MeshAnimation};
use proptest::prelude::*;
use tkio::{bvh, mdd, npy, obj, pc2, stl};

fn asset(rel: &str) -> Vec<u8> {
    let p = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/")).join(rel);
    std::fs::read(&p).unwrap_or_else(|e| panic!("test asset missing: {}: {e}", p.display()))
}

fn tri() -> Mesh {
    Mesh::new("t", vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]])
}

/// Small valid seeds of every format (real data, cut down so that each case is fast).
struct Seeds {
    obj: Vec<u8>,
    bvh: Vec<u8>,
    pc2: Vec<u8>,
    mdd: Vec<u8>,
    stl: Vec<u8>,
    npy: Vec<u8>,
}

fn seeds() -> &'static Seeds {
    static SEEDS: OnceLock<Seeds> = OnceLock::new();
    SEEDS.get_or_init(|| {
        let spot = obj::read(&asset("meshes/spot.obj")).unwrap();
        // First 40 triangles of Spot, re-indexed to the vertices they use.
        let mut small = Mesh::new("spot40", Vec::new(), Vec::new());
        let mut map = std::collections::HashMap::new();
        for t in &spot.triangles[..40] {
            let t = t.map(|i| {
                *map.entry(i).or_insert_with(|| {
                    small.positions.push(spot.positions[i as usize]);
                    (small.positions.len() - 1) as u32
                })
            });
            small.triangles.push(t);
        }
        let frames: Vec<Vec3> = (0..3)
            .flat_map(|f| small.positions.iter().map(move |p| *p * (1.0 + f as f32)))
            .collect();
        let anim = MeshAnimation::new(small.clone(), 24.0, frames).unwrap();
        let bvh_text = String::from_utf8(asset("mocap/12_03.bvh")).unwrap();
        let (head, motion) = bvh_text.split_once("MOTION").unwrap();
        let rows: Vec<&str> = motion.lines().skip(3).take(2).collect();
        let bvh = format!(
            "{head}MOTION\nFrames: 2\nFrame Time: .0083333\n{}\n",
            rows.join("\n")
        );
        Seeds {
            obj: obj::write(&small).into_bytes(),
            bvh: bvh.into_bytes(),
            pc2: pc2::write(&anim),
            mdd: mdd::write(&anim),
            stl: stl::write_binary(&small),
            npy: npy::write_f32(&[2, 3], &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).unwrap(),
        }
    })
}

fn rest_for(n: usize) -> Mesh {
    if n == 3 {
        tri()
    } else {
        Mesh::new("r", vec![Vec3::ZERO; n], Vec::new())
    }
}

/// Runs every reader on `data`; the only failure is a panic (propagated by proptest).
fn all_readers(data: &[u8]) {
    let _ = obj::read(data);
    let _ = bvh::read(data);
    let _ = stl::read(data);
    let _ = npy::read_f32(data);
    let _ = pc2::read(data, tri(), 24.0);
    let _ = mdd::read(data, tri(), 24.0);
    // Also with a rest mesh that matches the header, to reach the position decoding.
    if let Ok(h) = pc2::read_header(data) {
        let _ = pc2::read(data, rest_for(h.points.min(1 << 16)), 24.0);
    }
    if let Ok(h) = mdd::read_header(data) {
        let _ = mdd::read(data, rest_for(h.points.min(1 << 16)), 24.0);
    }
}

fn mutate(seed: &[u8], edits: &[(usize, u8)], cut: usize) -> Vec<u8> {
    let mut v = seed.to_vec();
    for &(at, byte) in edits {
        if !v.is_empty() {
            let i = at % v.len();
            v[i] = byte;
        }
    }
    v.truncate(v.len() - cut % (v.len() + 1) / 4);
    v
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_bytes_never_panic(data in proptest::collection::vec(any::<u8>(), 0..512)) {
        all_readers(&data);
    }

    #[test]
    fn arbitrary_text_never_panics(text in "[-0-9a-zA-Z/{}:. \\n]{0,400}") {
        all_readers(text.as_bytes());
        let with_header = format!("HIERARCHY\nROOT a\n{{\n{text}");
        let _ = bvh::read(with_header.as_bytes());
        let with_v = format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{text}");
        let _ = obj::read(with_v.as_bytes());
    }

    #[test]
    fn edited_real_files_never_panic(
        edits in proptest::collection::vec((any::<usize>(), any::<u8>()), 1..8),
        cut in any::<usize>(),
    ) {
        let s = seeds();
        for seed in [&s.obj, &s.bvh, &s.pc2, &s.mdd, &s.stl, &s.npy] {
            all_readers(&mutate(seed, &edits, cut));
        }
    }
}

#[test]
fn seeds_are_valid_files() {
    let s = seeds();
    assert_eq!(obj::read(&s.obj).unwrap().triangle_count(), 40);
    let scene = bvh::read(&s.bvh).unwrap();
    assert_eq!(scene.nodes.len(), 38);
    let n = pc2::read_header(&s.pc2).unwrap().points;
    assert_eq!(
        pc2::read(&s.pc2, rest_for(n), 24.0).unwrap().frame_count(),
        3
    );
    assert_eq!(
        mdd::read(&s.mdd, rest_for(n), 24.0).unwrap().frame_count(),
        3
    );
    assert_eq!(stl::read(&s.stl).unwrap().triangle_count(), 40);
    assert_eq!(npy::read_f32(&s.npy).unwrap().0, vec![2, 3]);
}
