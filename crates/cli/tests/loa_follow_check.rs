//! An independent check of how closely `toonkit loa animate` makes the bundled robot follow
//! the line, not taking the tool's own figure: the joints are read back from the written
//! glTF with the `gltf` crate, not toonkit's reader (node hierarchy × the written animation),
//! one front view (scale and offset, no rotation) is fitted per shot to put them on the line written by `toonkit loa line`, and every
//! measured joint's distance to the line's polyline is taken per frame, as a fraction of the
//! line's length.

mod common;

use std::path::Path;

use common::{data, json};
use glam::{DVec2, Mat4, Quat, Vec3};

/// An untuned moving sequence: an upright stroke, two arcs leaning either way and an
/// upright stroke again, drawn from the feet up (screen coordinates, y down).
const MOVING: &str = r#"{"keystrokes": [
  {"frame": 0,  "points": [[300, 500], [300, 400], [300, 300], [300, 200]]},
  {"frame": 12, "points": [[320, 500], [350, 420], [385, 330], [430, 240]]},
  {"frame": 24, "points": [[360, 490], [395, 400], [390, 300], [350, 210]]},
  {"frame": 36, "points": [[400, 500], [402, 400], [401, 300], [400, 200]]}
]}"#;

/// One keystroke held from frame 0 to frame 24.
const STATIC: &str = r#"{"keystrokes": [
  {"frame": 0,  "points": [[300, 500], [310, 400], [315, 300], [312, 200]]},
  {"frame": 24, "points": [[300, 500], [310, 400], [315, 300], [312, 200]]}
]}"#;

/// Distances of the measured joints to the line over every frame.
struct Distances {
    mean: f64,
    p95: f64,
    worst: f64,
}

/// One animated property of a node: key times and values (translation/scale `[x, y, z, 0]`,
/// rotation `[x, y, z, w]`), linear (spherical for rotations) or step.
struct Track {
    node: usize,
    property: gltf::animation::Property,
    step: bool,
    times: Vec<f32>,
    values: Vec<[f32; 4]>,
}

impl Track {
    fn at(&self, t: f32) -> [f32; 4] {
        let i = self.times.partition_point(|&x| x <= t);
        if i == 0 {
            return self.values[0];
        }
        if i == self.times.len() || self.step {
            return self.values[i - 1];
        }
        let (t0, t1) = (self.times[i - 1], self.times[i]);
        let u = ((t - t0) / (t1 - t0).max(f32::MIN_POSITIVE)).clamp(0.0, 1.0);
        let (a, b) = (self.values[i - 1], self.values[i]);
        if self.property == gltf::animation::Property::Rotation {
            Quat::from_array(a).slerp(Quat::from_array(b), u).to_array()
        } else {
            std::array::from_fn(|k| a[k] + u * (b[k] - a[k]))
        }
    }
}

/// World positions of the joints `names`, frame by frame, read from the glTF at `path` with
/// the `gltf` crate (not toonkit's own reader): node rest transforms, the first animation's
/// channels sampled at each frame, composed down the node hierarchy.
fn joints_from_gltf(path: &Path, names: &[String], frames: usize, fps: f32) -> Vec<Vec<Vec3>> {
    use gltf::animation::util::ReadOutputs;
    use gltf::animation::{Interpolation, Property};
    let (doc, buffers, _) = gltf::import(path).unwrap();
    let rest: Vec<(Vec3, Quat, Vec3)> = doc
        .nodes()
        .map(|n| {
            let (t, r, s) = n.transform().decomposed();
            (Vec3::from(t), Quat::from_array(r), Vec3::from(s))
        })
        .collect();
    let mut parent = vec![None; rest.len()];
    for n in doc.nodes() {
        for c in n.children() {
            parent[c.index()] = Some(n.index());
        }
    }
    let animation = doc
        .animations()
        .next()
        .expect("no animation in the written glTF");
    let tracks: Vec<Track> = animation
        .channels()
        .map(|c| {
            let reader = c.reader(|b| Some(&buffers[b.index()]));
            let property = c.target().property();
            let interpolation = c.sampler().interpolation();
            assert!(
                interpolation != Interpolation::CubicSpline,
                "cubic-spline channel not read by this check"
            );
            let values: Vec<[f32; 4]> = match reader.read_outputs().unwrap() {
                ReadOutputs::Translations(v) | ReadOutputs::Scales(v) => {
                    v.map(|[x, y, z]| [x, y, z, 0.0]).collect()
                }
                ReadOutputs::Rotations(r) => r.into_f32().collect(),
                ReadOutputs::MorphTargetWeights(_) => Vec::new(),
            };
            Track {
                node: c.target().node().index(),
                property,
                step: interpolation == Interpolation::Step,
                times: reader.read_inputs().unwrap().collect(),
                values,
            }
        })
        .filter(|t| t.property != Property::MorphTargetWeights)
        .collect();
    let nodes: Vec<usize> = names
        .iter()
        .map(|n| {
            doc.nodes()
                .position(|node| node.name() == Some(n.as_str()))
                .unwrap_or_else(|| panic!("no node {n} in the written glTF"))
        })
        .collect();
    (0..frames)
        .map(|f| {
            let t = f as f32 / fps;
            let mut local = rest.clone();
            for track in &tracks {
                let v = track.at(t);
                let l = &mut local[track.node];
                match track.property {
                    Property::Translation => l.0 = Vec3::new(v[0], v[1], v[2]),
                    Property::Rotation => l.1 = Quat::from_array(v).normalize(),
                    Property::Scale => l.2 = Vec3::new(v[0], v[1], v[2]),
                    Property::MorphTargetWeights => {}
                }
            }
            let world = |mut n: usize| {
                let mut m = Mat4::IDENTITY;
                loop {
                    let (t, r, s) = local[n];
                    m = Mat4::from_scale_rotation_translation(s, r, t) * m;
                    match parent[n] {
                        Some(p) => n = p,
                        None => return m,
                    }
                }
            };
            nodes.iter().map(|&n| world(n).w_axis.truncate()).collect()
        })
        .collect()
}

/// Distance of `p` to the polyline `line`.
fn to_polyline(p: DVec2, line: &[DVec2]) -> f64 {
    line.windows(2)
        .map(|s| {
            let d = s[1] - s[0];
            let t = ((p - s[0]).dot(d) / d.length_squared().max(1e-300)).clamp(0.0, 1.0);
            (p - (s[0] + t * d)).length()
        })
        .fold(f64::INFINITY, f64::min)
}

fn closest_on_polyline(p: DVec2, line: &[DVec2]) -> DVec2 {
    let mut best = (f64::INFINITY, line[0]);
    for s in line.windows(2) {
        let d = s[1] - s[0];
        let t = ((p - s[0]).dot(d) / d.length_squared().max(1e-300)).clamp(0.0, 1.0);
        let q = s[0] + t * d;
        if (p - q).length() < best.0 {
            best = ((p - q).length(), q);
        }
    }
    best.1
}

/// Fits one front view `screen = s · (x, −y) + t` of the joints onto the lines (iterated
/// closest points, a linear least-squares fit per iteration), then measures.
fn measure(joints: &[Vec<Vec3>], lines: &[Vec<DVec2>]) -> Distances {
    let front = |p: Vec3| DVec2::new(p.x as f64, -(p.y as f64));
    // Start: the first frame's joints scaled to the line's extent, centred on it.
    let extent = |pts: &[DVec2]| {
        let (lo, hi) = pts.iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        (0.5 * (lo + hi), (hi - lo).length())
    };
    let first: Vec<DVec2> = joints[0].iter().map(|p| front(*p)).collect();
    let (c_j, e_j) = extent(&first);
    let (c_l, e_l) = extent(&lines[0]);
    let mut s = e_l / e_j.max(1e-12);
    let mut t = c_l - s * c_j;
    for _ in 0..50 {
        // Closest line points, then the best scale and offset for those pairs.
        let pairs: Vec<(DVec2, DVec2)> = joints
            .iter()
            .zip(lines)
            .flat_map(|(js, line)| {
                js.iter().map(move |p| {
                    let x = front(*p);
                    (x, closest_on_polyline(s * x + t, line))
                })
            })
            .collect();
        let n = pairs.len() as f64;
        let mx = pairs.iter().map(|p| p.0).sum::<DVec2>() / n;
        let my = pairs.iter().map(|p| p.1).sum::<DVec2>() / n;
        let sxy: f64 = pairs.iter().map(|(x, y)| (*x - mx).dot(*y - my)).sum();
        let sxx: f64 = pairs.iter().map(|(x, _)| (*x - mx).length_squared()).sum();
        s = sxy / sxx.max(1e-300);
        t = my - s * mx;
    }
    let mut d: Vec<f64> = joints
        .iter()
        .zip(lines)
        .flat_map(|(js, line)| {
            let length: f64 = line.windows(2).map(|w| (w[1] - w[0]).length()).sum();
            js.iter()
                .map(move |p| to_polyline(s * front(*p) + t, line) / length)
        })
        .collect();
    d.sort_by(f64::total_cmp);
    Distances {
        mean: d.iter().sum::<f64>() / d.len() as f64,
        p95: d[((0.95 * d.len() as f64).ceil() as usize).clamp(1, d.len()) - 1],
        worst: d[d.len() - 1],
    }
}

/// Animates the robot along `keys` (default options) and measures the written glTF against
/// the written line; also returns the tool's own summary.
fn check(keys: &str, name: &str) -> (Distances, serde_json::Value) {
    let dir = tempfile::tempdir().unwrap();
    let k = dir.path().join(format!("{name}.json"));
    std::fs::write(&k, keys).unwrap();
    let (k, glb, line) = (
        k.to_str().unwrap().to_string(),
        dir.path().join(format!("{name}.glb")),
        dir.path().join(format!("{name}-line.json")),
    );
    json(&["loa", "line", &k, "-o", line.to_str().unwrap()]);
    let robot = data("characters/RobotExpressive.glb");
    let report = json(&[
        "loa",
        "animate",
        robot.to_str().unwrap(),
        &k,
        "-o",
        glb.to_str().unwrap(),
        // The gltf crate refuses KHR_mesh_quantization; the skeleton and clip are the same.
        "--no-quantize",
    ]);
    let written: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&line).unwrap()).unwrap();
    let lines: Vec<Vec<DVec2>> = written["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            f["points"]
                .as_array()
                .unwrap()
                .iter()
                .map(|p| DVec2::new(p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
                .collect()
        })
        .collect();
    // The joints the tool says it constrains (a leaf's tip has no node of its own).
    let names: Vec<String> = report["line_distance_joints"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|n| n.as_str())
        .filter(|n| !n.ends_with("(tip)"))
        .map(str::to_string)
        .collect();
    assert!(names.len() >= 3, "{report:#}");
    let fps = report["fps"].as_f64().unwrap() as f32;
    let joints = joints_from_gltf(&glb, &names, lines.len(), fps);
    let d = measure(&joints, &lines);
    println!(
        "{name}: joints {names:?}; independent mean {:.2} %, p95 {:.2} %, worst {:.2} %; \
         the tool's mean {:.2} %, p95 {:.2} %, worst {}",
        100.0 * d.mean,
        100.0 * d.p95,
        100.0 * d.worst,
        report["line_distance_mean_percent"].as_f64().unwrap(),
        report["line_distance_p95_percent"].as_f64().unwrap(),
        report["line_distance_worst"],
    );
    (d, report)
}

#[test]
fn robot_follows_an_untuned_moving_line_by_an_independent_reading_of_the_gltf() {
    let (d, report) = check(MOVING, "moving");
    assert!(d.mean <= 0.05, "mean {}", d.mean);
    assert!(d.p95 <= 0.08, "p95 {}", d.p95);
    // The tool's worst point is a real point: never below the mean it reports.
    let worst = report["line_distance_worst"]["percent"].as_f64().unwrap();
    assert!(worst >= report["line_distance_p95_percent"].as_f64().unwrap());
    assert!(report["line_distance_worst"]["joint"].is_string());
    assert!(report["line_distance_unmeasured_frames"].is_array());
}

#[test]
fn robot_on_a_held_line_by_an_independent_reading_of_the_gltf() {
    let (d, _) = check(STATIC, "static");
    assert!(d.mean <= 0.03, "mean {}", d.mean);
}
