//! Files written by real exporters (made by `.ci/io.sh`: Blender 4.2 for glTF, glTF with a
//! light, FBX; glTF-Transform for Draco; gltfpack for meshopt + quantization) read like the
//! plain glTF Blender wrote of the same scene: same clips with the same frame counts, and
//! positions within the compression's error at the first, middle and last frame.
//!
//! Vertex order and splitting differ between exporters (Draco reorders, FBX keeps Blender's
//! vertices), so positions are compared as point sets: the largest distance from a vertex of
//! one file to the nearest vertex of the other, both ways, relative to the bounding-box
//! diagonal. Runs when `TOONKIT_IO_EXPORTS` names the folder; `.ci/io.sh` sets it.

use std::path::{Path, PathBuf};

use anim::glam::Vec3;
use anim::{SampleOptions, Scene};

const FPS: f32 = 24.0;

fn exports() -> Option<PathBuf> {
    std::env::var_os("TOONKIT_IO_EXPORTS").map(PathBuf::from)
}

fn load(path: &Path) -> (Scene, Vec<String>) {
    let (loaded, notes) = tkio::load_with_notes(path, &tkio::LoadOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
    match loaded {
        tkio::Loaded::Scene(s) => (*s, notes),
        _ => panic!("{}: not a scene", path.display()),
    }
}

/// All vertices of every object at frames first, middle, last of `clip` (rest pose: None).
fn frames(scene: &Scene, clip: Option<usize>) -> Vec<Vec<Vec3>> {
    let s = anim::sample(
        scene,
        &SampleOptions {
            fps: FPS,
            clip,
            ..Default::default()
        },
    )
    .unwrap();
    let n = s
        .objects
        .iter()
        .map(|o| o.animation.frame_count())
        .max()
        .unwrap_or(1);
    let picks = if clip.is_some() {
        vec![0, n / 2, n - 1]
    } else {
        vec![0]
    };
    picks
        .into_iter()
        .map(|f| {
            s.objects
                .iter()
                .flat_map(|o| {
                    o.animation
                        .frame(f.min(o.animation.frame_count() - 1))
                        .to_vec()
                })
                .collect()
        })
        .collect()
}

/// Largest distance from a point of `a` to its nearest point of `b` (points sorted by x).
fn directed(a: &[Vec3], b: &[Vec3]) -> f32 {
    let mut b: Vec<Vec3> = b.to_vec();
    b.sort_by(|p, q| p.x.total_cmp(&q.x));
    let mut worst = 0.0f32;
    for p in a {
        let k = b.partition_point(|q| q.x < p.x);
        let mut best = f32::MAX;
        for q in b[k..].iter() {
            if q.x - p.x > best {
                break;
            }
            best = best.min(p.distance(*q));
        }
        for q in b[..k].iter().rev() {
            if p.x - q.x > best {
                break;
            }
            best = best.min(p.distance(*q));
        }
        worst = worst.max(best);
    }
    worst
}

fn diagonal(points: &[Vec3]) -> f32 {
    let lo = points.iter().fold(Vec3::splat(f32::MAX), |a, p| a.min(*p));
    let hi = points.iter().fold(Vec3::splat(f32::MIN), |a, p| a.max(*p));
    (hi - lo).length()
}

/// Compares `other` with the reference; `tolerance` relative to the diagonal; `animated`:
/// also every clip's frame count and its first, middle and last frames.
fn compare(reference: &Path, other: &Path, tolerance: f32, animated: bool) -> f32 {
    let (mut a, _) = load(reference);
    let (mut b, notes) = load(other);
    if !animated {
        // The rest pose only (without clips, `frames` samples it).
        a.clips.clear();
        b.clips.clear();
    }
    println!("{}: {}", other.display(), notes.join("; "));
    let mut pairs = vec![(None, None)];
    if animated {
        assert_eq!(
            a.clips.len(),
            b.clips.len(),
            "{}: clip count",
            other.display()
        );
        for (i, c) in a.clips.iter().enumerate() {
            // Blender's FBX exporter names a stack `Armature|Action` (the glTF importer named
            // the action `Dance_RobotArmature`).
            // A single clip on both sides is the same animation (Blender bakes a shape-key
            // animation into one FBX stack named after the scene).
            let single = (a.clips.len() == 1 && b.clips.len() == 1).then_some(0);
            let j = single
                .or_else(|| {
                    b.clips.iter().position(|d| {
                        let action = d.name.split('|').nth(1).unwrap_or(&d.name);
                        d.name == c.name
                            || action == c.name
                            || action.starts_with(&format!("{}_", c.name))
                    })
                })
                .unwrap_or_else(|| {
                    let names: Vec<&str> = b.clips.iter().map(|d| d.name.as_str()).collect();
                    panic!("{}: no clip {} in {names:?}", other.display(), c.name)
                });
            assert_eq!(
                c.frame_count(FPS),
                b.clips[j].frame_count(FPS),
                "{}: frames of clip {}",
                other.display(),
                c.name
            );
            pairs.push((Some(i), Some(j)));
        }
        pairs.truncate(4); // rest pose and three clips: enough, and quick
    }
    let mut worst = 0.0f32;
    for (ca, cb) in pairs {
        let (fa, fb) = (frames(&a, ca), frames(&b, cb));
        for (pa, pb) in fa.iter().zip(&fb) {
            let d = directed(pa, pb).max(directed(pb, pa)) / diagonal(pa);
            worst = worst.max(d);
        }
    }
    println!(
        "{}: largest distance {worst:.2e} of the diagonal (tolerance {tolerance:.0e})",
        other.display()
    );
    assert!(
        worst <= tolerance,
        "{}: {worst} > {tolerance}",
        other.display()
    );
    worst
}

/// The largest position error gltfpack's quantization allows, relative to the diagonal of
/// the rest pose. gltfpack puts every mesh on one grid: 14 bits over the largest extent of all
/// meshes in their own (mesh) coordinates, so a mesh whose node scales it up gets the grid
/// scaled up too in the world (the robot's hands sit under nodes of scale 100: 4.2e-3 of the
/// diagonal, where an unscaled mesh gets ~1e-4; without quantization, `-noq`, the robot reads
/// back within 6e-8).
fn gltfpack_bound(scene: &Scene) -> f32 {
    // The grid covers the meshes and their morph targets.
    let points = scene.meshes.iter().flat_map(|m| {
        let base = &m.mesh.positions;
        let targets = m
            .morph_targets
            .iter()
            .flat_map(move |t| base.iter().zip(&t.positions).map(|(p, d)| *p + *d));
        base.iter().copied().chain(targets)
    });
    let lo = points.clone().fold(Vec3::splat(f32::MAX), |a, p| a.min(p));
    let hi = points.fold(Vec3::splat(f32::MIN), |a, p| a.max(p));
    let step = (hi - lo).max_element() / ((1 << 14) - 1) as f32;
    let mut rest = scene.clone();
    rest.clips.clear();
    let s = anim::sample(&rest, &SampleOptions::default()).unwrap();
    let scale_of = |m: anim::glam::Mat4| {
        (0..3)
            .map(|k| m.col(k).truncate().length())
            .fold(0.0f32, f32::max)
    };
    let mut scale = 0.0f32;
    for node in scene.mesh_nodes() {
        let n = &scene.nodes[node];
        scale = scale.max(match n.skin {
            Some(k) => {
                let skin = &scene.skins[k];
                skin.joints
                    .iter()
                    .zip(&skin.inverse_bind)
                    .map(|(&j, ib)| scale_of(s.node_world[j] * *ib))
                    .fold(0.0f32, f32::max)
            }
            None => scale_of(s.node_world[node]),
        });
    }
    let all: Vec<Vec3> = s
        .objects
        .iter()
        .flat_map(|o| o.animation.frame(0).to_vec())
        .collect();
    // Half a step per axis (twice with morph targets: gltfpack rounds the base and the
    // deltas), plus the f32 rounding of the dequantization.
    let roundings = if scene.meshes.iter().any(|m| !m.morph_targets.is_empty()) {
        2.0
    } else {
        1.0
    };
    (roundings * 0.5 * step * 3f32.sqrt() * scale) / diagonal(&all) + 1e-6
}

#[test]
fn files_of_real_exporters_read_like_the_plain_gltf() {
    let Some(dir) = exports() else {
        println!("TOONKIT_IO_EXPORTS is not set (.ci/io.sh sets it): nothing to compare");
        return;
    };
    let mut checked = 0;
    for name in ["RobotExpressive", "CesiumMan", "AnimatedMorphSphere"] {
        let reference = dir.join(format!("{name}.glb"));
        if !reference.exists() {
            continue;
        }
        // gltfpack resamples animation and quantizes keys: its rest pose is compared with the
        // bound of its position quantization.
        let (scene, _) = load(&reference);
        let gltfpack = gltfpack_bound(&scene);
        println!("{name}: gltfpack's position grid allows {gltfpack:.2e} of the diagonal");
        let cases = [
            (format!("{name}_lights.glb"), 1e-5, true),
            (format!("{name}_draco.glb"), 1e-3, true),
            (format!("{name}.fbx"), 1e-5, true),
            (format!("{name}_gltfpack.glb"), gltfpack, false),
        ];
        for (file, tolerance, animated) in cases {
            let path = dir.join(&file);
            assert!(path.exists(), "{} is missing", path.display());
            compare(&reference, &path, tolerance, animated);
            checked += 1;
        }
    }
    assert!(checked >= 4, "no exported file found in {}", dir.display());
}

/// ASCII FBX 7.5 written by a second real exporter (Assimp, Debian's `assimp-utils`; Blender
/// writes binary FBX only): the geometry toonkit reads equals Assimp's own reading of the same
/// file (`{name}_ascii.obj`, which ignores the file's units) once the declared centimetres are
/// converted to metres (rest pose); the file's animation stack is read as a clip.
#[test]
fn ascii_fbx_reads_like_its_exporter_reads_it() {
    let Some(dir) = exports() else {
        println!("TOONKIT_IO_EXPORTS is not set (.ci/io.sh sets it): nothing to compare");
        return;
    };
    let mut checked = 0;
    for name in ["CesiumMan", "AnimatedMorphSphere"] {
        let fbx = dir.join(format!("{name}_ascii.fbx"));
        if !fbx.exists() {
            continue;
        }
        let head = std::fs::read(&fbx).unwrap();
        assert!(
            head.starts_with(b"; FBX"),
            "{}: not ASCII FBX",
            fbx.display()
        );
        let (scene, notes) = load(&fbx);
        assert!(
            notes.iter().any(|n| n.contains("ASCII")) && notes.iter().any(|n| n.contains("0.01 m")),
            "{}: {notes:?}",
            fbx.display()
        );
        assert_eq!(
            scene.clips.len(),
            1,
            "{}: one animation stack",
            fbx.display()
        );
        // The rest pose as every tool samples it (node transforms applied), in Assimp's units.
        let mut rest = scene.clone();
        rest.clips.clear();
        let ours: Vec<Vec3> = frames(&rest, None)[0].iter().map(|p| *p * 100.0).collect();
        let obj = dir.join(format!("{name}_ascii.obj"));
        let bytes = std::fs::read(&obj).unwrap_or_else(|e| panic!("{}: {e}", obj.display()));
        let theirs = tkio::obj::read(&bytes).unwrap().positions;
        let d = directed(&ours, &theirs).max(directed(&theirs, &ours)) / diagonal(&theirs);
        println!(
            "{}: {} vertices, {} clip(s), largest distance to Assimp's reading {d:.2e} of the diagonal",
            fbx.display(),
            ours.len(),
            scene.clips.len()
        );
        assert!(d <= 1e-5, "{}: {d}", fbx.display());
        checked += 1;
    }
    assert!(checked >= 1, "no ASCII FBX found in {}", dir.display());
}
