//! Real characters read with the glTF reader: every clip gives finite offsets within
//! [−1.5, 1.5] (SMEAR Eq. 9 may slightly exceed [−1, 1] at joints, paper Section 3.2).

use std::path::PathBuf;

use anim::{sample, SampleOptions};
use smear::{OffsetMode, OffsetOptions, OffsetSolver, SurfacePoint};

fn data(name: &str) -> PathBuf {
    let p = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../assets/characters/"
    ))
    .join(name);
    assert!(p.exists(), "test asset missing: {}", p.display());
    p
}

fn check_clips(file: &str, options: &OffsetOptions) -> usize {
    let path = data(file);
    let scene = tkio::gltf::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(!scene.clips.is_empty(), "{file} has clips");
    let mut checked = 0;
    for c in 0..scene.clips.len() {
        let sampled = sample(
            &scene,
            &SampleOptions {
                clip: Some(c),
                ..SampleOptions::default()
            },
        )
        .unwrap();
        let solver = OffsetSolver::new(&sampled, options).unwrap();
        let all = solver.all();
        assert_eq!(all.len(), sampled.objects.len());
        let mut any_moving = false;
        for (i, d) in all.iter().enumerate() {
            assert_eq!(d.frame_count(), sampled.frame_count);
            assert_eq!(
                d.vertex_count(),
                sampled.objects[i].animation.vertex_count()
            );
            let (lo, hi) = d.range();
            assert!(
                d.values().iter().all(|x| x.is_finite()) && lo >= -1.5 && hi <= 1.5,
                "{file} clip '{}' object '{}': range [{lo}, {hi}]",
                scene.clips[c].name,
                sampled.objects[i].name
            );
            println!(
                "{file} '{}' {}: [{lo:.3}, {hi:.3}]",
                scene.clips[c].name, sampled.objects[i].name
            );
            any_moving |= d.max_abs() > 0.5;
        }
        assert!(
            any_moving || sampled.frame_count <= 2,
            "{file} clip '{}' gives no offsets",
            scene.clips[c].name
        );
        checked += 1;
    }
    checked
}

#[test]
fn robot_expressive_every_clip() {
    assert_eq!(
        check_clips("RobotExpressive.glb", &OffsetOptions::default()),
        14
    );
}

#[test]
fn cesium_man_walk() {
    assert_eq!(check_clips("CesiumMan.glb", &OffsetOptions::default()), 1);
    let whole = OffsetOptions {
        whole_body: true,
        ..OffsetOptions::default()
    };
    assert_eq!(check_clips("CesiumMan.glb", &whole), 1);
}

#[test]
fn cesium_man_articulated_surface_points() {
    let scene = tkio::gltf::read(&data("CesiumMan.glb")).unwrap();
    let sampled = sample(&scene, &SampleOptions::default()).unwrap();
    let solver = OffsetSolver::new(&sampled, &OffsetOptions::default()).unwrap();
    assert_eq!(solver.mode(0), Some(OffsetMode::Articulated));
    let tris = sampled.objects[0].animation.mesh.triangle_count();
    let pts: Vec<SurfacePoint> = (0..tris)
        .step_by(37)
        .map(|t| SurfacePoint {
            triangle: t as u32,
            barycentric: [0.2, 0.3, 0.5],
        })
        .collect();
    let d = solver.surface_offsets(0, &pts).unwrap();
    assert!(d.values().iter().all(|x| x.is_finite() && x.abs() <= 1.5));
    assert!(d.max_abs() > 0.5);
}
