//! The whole pipeline of [`super::animate`]: setup, planar stage, 3D stage, measurements.

use std::collections::BTreeMap;

use glam::{DQuat, DVec2, DVec3};

use super::bones::{self, BoneSet, ChainPoint, Preset};
use super::camera::{ActionCamera, ActionPlane, ScreenMap};
use super::contacts::contact_trajectories;
use super::error::AnimateError;
use super::keys::{BoneSetKey, ContactKey, TwistKey};
use super::reduction::Reduction;
use super::release;
use super::rig::{Rig, WorldPose};
use super::solver::{Poses, Stage, StageReport, DEFAULT_TOLERANCE, STAGING_TOLERANCE};
use super::targets::{
    image_lines, line_targets, twist_target, ContactTarget, FrameTargets, ImageLine, KeyChain,
    OrientTarget,
};
use super::terms::{log, point_position, Columns};
use super::{AnimateOptions, AnimateReport, Character, Motion, WorstPoint, DEFAULT_MAX_ITERATIONS};
use crate::Animation;

fn joint_index(rig: &Rig, name: &str) -> Result<usize, AnimateError> {
    rig.names
        .iter()
        .position(|n| n == name)
        .ok_or_else(|| AnimateError::UnknownJoint {
            name: name.to_string(),
            joints: rig.names.join(", "),
        })
}

/// The bone set of every keystroke.
fn key_sets(line: &Animation, sets: &[BoneSetKey]) -> Result<Vec<BoneSet>, AnimateError> {
    let frames = &line.keystroke_frames;
    for s in sets {
        if !frames.contains(&s.frame) {
            return Err(AnimateError::BadFrame {
                what: "bone set",
                frame: s.frame,
                expected: format!("bone sets go on keystroke frames {frames:?}"),
            });
        }
    }
    let mut current = sets
        .iter()
        .min_by_key(|s| s.frame)
        .map_or(BoneSet::Preset(Preset::RightLegSpineHead), |s| {
            s.set.clone()
        });
    Ok(frames
        .iter()
        .map(|f| {
            if let Some(s) = sets.iter().rev().find(|s| s.frame == *f) {
                current = s.set.clone();
            }
            current.clone()
        })
        .collect())
}

/// Default screen map: one scale for all keystrokes, fitted by least squares so that every
/// keystroke's line length matches its bone set's length (`s = Σ C_k S_k / Σ S_k²` over the
/// keystrokes' screen lengths `S_k` and chain lengths `C_k`); the first keystroke's arc-length
/// midpoint lands on its chain's midpoint.
fn fit_screen(
    line: &Animation,
    key_offsets: &[usize],
    keys: &[KeyChain],
    image: &[DVec2],
) -> ScreenMap {
    let (mut cs, mut ss) = (0.0, 0.0);
    for (&k, chain) in key_offsets.iter().zip(keys) {
        let screen = ImageLine::new(line.frames[k].chain.joints()).length();
        if screen > 0.0 && chain.length > 0.0 {
            cs += chain.length * screen;
            ss += screen * screen;
        }
    }
    let scale = if ss > 0.0 { cs / ss } else { 1.0 };
    let chain = &keys[0];
    let screen = ImageLine::new(line.frames[key_offsets[0]].chain.joints());
    // The chain's midpoint by 3D arc length.
    let k = chain
        .u
        .partition_point(|&u| u <= 0.5)
        .clamp(1, image.len().max(2) - 1);
    let (u0, u1) = (chain.u[k - 1], chain.u[k]);
    let t = if u1 > u0 { (0.5 - u0) / (u1 - u0) } else { 0.0 };
    let origin = image
        .get(k - 1)
        .copied()
        .unwrap_or_default()
        .lerp(image.get(k).copied().unwrap_or_default(), t);
    ScreenMap {
        anchor: screen.at(0.5),
        origin,
        scale,
    }
}

/// Marks the joints whose rotation moves chain point `p`.
fn mark_ancestors(rig: &Rig, p: ChainPoint, dof: &mut [bool]) {
    let mut a = match p {
        ChainPoint::Joint(j) => rig.parent[j],
        ChainPoint::Tip(j) => Some(j),
    };
    while let Some(k) = a {
        dof[k] = true;
        a = rig.parent[k];
    }
}

/// The space-time solve's unknowns (nodes × columns, LoA §4) against
/// [`anim::budget::DEFAULT_MAX_SOLVER_UNKNOWNS`]: its dense normal equations hold their square.
fn check_unknowns(nodes: usize, columns: usize) -> Result<(), AnimateError> {
    anim::check_budget(
        "space-time unknowns (nodes × degrees of freedom)",
        anim::budget::product(&[nodes as u64, columns as u64]),
        anim::budget::DEFAULT_MAX_SOLVER_UNKNOWNS,
        "use fewer keystrokes or smaller bone sets",
    )?;
    Ok(())
}

pub(crate) fn run(
    character: &Character,
    line: &Animation,
    bone_sets: &[BoneSetKey],
    contacts: &[ContactKey],
    twists: &[TwistKey],
    options: &AnimateOptions,
) -> Result<Motion, AnimateError> {
    let rig = &character.rig;
    let frames = line.frames.len();
    if frames == 0 || line.keystroke_frames.is_empty() {
        return Err(AnimateError::EmptyLine);
    }
    let first = line.frames[0].frame;
    let last = first + frames as i64 - 1;
    let key_offsets: Vec<usize> = line
        .keystroke_frames
        .iter()
        .map(|&k| (k - first).clamp(0, frames as i64 - 1) as usize)
        .collect();
    let max_iterations = if options.max_iterations == 0 {
        DEFAULT_MAX_ITERATIONS
    } else {
        options.max_iterations
    };
    let weights = &options.weights;

    // Setup: initial pose, camera, plane, chains, screen map.
    let initial = rig.world(&rig.rotation, DVec3::ZERO);
    let (bmin, bmax) = character.bounds();
    let camera = options
        .camera
        .unwrap_or_else(|| ActionCamera::front_fitted(bmin, bmax));
    let plane = ActionPlane::new(options.plane_normal.unwrap_or(camera.forward))?;
    let height = character.height();
    let sets = key_sets(line, bone_sets)?;
    let chains: Vec<_> = sets
        .iter()
        .map(|s| bones::resolve(rig, s))
        .collect::<Result<_, _>>()?;
    let keys: Vec<KeyChain> = chains
        .iter()
        .map(|c| KeyChain::new(rig, &initial, &camera, c))
        .collect();
    let ref_length = keys
        .iter()
        .map(|k| k.length)
        .fold(0.0, f64::max)
        .max(height * 1e-6);
    let screen = options.screen.unwrap_or_else(|| {
        let image: Vec<DVec2> = keys[0]
            .points
            .iter()
            .map(|&p| camera.project(point_position(rig, &initial, p)))
            .collect();
        fit_screen(line, &key_offsets, &keys, &image)
    });
    let lines = image_lines(line, &screen);
    let mut targets: Vec<FrameTargets> = vec![FrameTargets::default(); frames];
    for (f, t) in targets.iter_mut().enumerate() {
        line_targets(&keys, &key_offsets, f, &lines[f], t);
    }
    // Settle frames after the last keystroke get their own interval of nodes, ending on the
    // clip's last frame.
    let mut node_keys = line.keystroke_frames.clone();
    if node_keys.last().is_some_and(|&k| k < last) {
        node_keys.push(last);
    }
    let reduction = Reduction::new(&node_keys);

    // Planar stage (Section 4).
    let mut dof = vec![false; rig.len()];
    for k in &keys {
        for &p in &k.points {
            mark_ancestors(rig, p, &mut dof);
        }
    }
    // The turn joint of a chain (pelvis, chest) carries a sideways branch connector: turning
    // it, or any of its ancestors, swaps the connector's side — a discrete flip the solver
    // takes mid-clip (the children counter-rotating) when it starts from the initial pose.
    // So the planar stage is a continuation: a first solve holds the turn joints and their
    // ancestors at their initial orientation (limbs and spine turn, the root translates),
    // which stages the pose without any flip; a second solve frees them (the pelvis tilts
    // and turns the whole body), starting from that solution, so they only refine it.
    // `hold_pelvis` stops after the first solve.
    let mut held = dof.clone();
    for k in &keys {
        for (i, c) in k.connector.iter().enumerate() {
            if let (true, Some(&ChainPoint::Joint(turn))) = (*c, k.points.get(i + 1)) {
                let mut a = Some(turn);
                while let Some(x) = a {
                    held[x] = false;
                    a = rig.parent[x];
                }
            }
        }
    }
    let mut poses = Poses {
        joints: rig.len(),
        rotations: (0..frames)
            .flat_map(|_| rig.rotation.iter().copied())
            .collect(),
        offsets: vec![DVec3::ZERO; frames],
    };
    let planar_stage = |dof: &[bool]| Stage {
        rig,
        camera: &camera,
        cols: Columns::new(rig, dof, &[plane.normal], &[plane.u, plane.v]),
        targets: &targets,
        reduction: &reduction,
        weights,
        ref_length,
        height,
    };
    check_unknowns(reduction.nodes(), planar_stage(&dof).cols.len())?;
    let staging = !options.hold_pelvis && held != dof;
    let tolerance = if staging {
        STAGING_TOLERANCE
    } else {
        DEFAULT_TOLERANCE
    };
    let mut planar = planar_stage(&held).solve(&mut poses, max_iterations, tolerance);
    if staging {
        let free = planar_stage(&dof).solve(&mut poses, max_iterations, DEFAULT_TOLERANCE);
        planar = StageReport {
            unknowns: free.unknowns,
            iterations: planar.iterations + free.iterations,
            initial_energy: planar.initial_energy,
            final_energy: free.final_energy,
        };
    }

    // 3D stage (Section 4.1).
    let mut spatial = None;
    let mut contact_targets: Vec<Vec<ContactTarget>> = vec![Vec::new(); frames];
    if !contacts.is_empty() || !twists.is_empty() {
        let worlds = poses.worlds(rig);
        let frame_index = |what: &'static str, f: i64| -> Result<usize, AnimateError> {
            if f < first || f > last {
                return Err(AnimateError::BadFrame {
                    what,
                    frame: f,
                    expected: format!("the line covers frames {first}..={last}"),
                });
            }
            Ok((f - first) as usize)
        };
        let trajectories = contact_trajectories(
            rig,
            &worlds,
            contacts,
            |name| joint_index(rig, name),
            |f| frame_index("contact", f),
        )?;
        contact_targets = trajectories.held;
        let mut twist_by_joint: BTreeMap<usize, Vec<(usize, f64)>> = BTreeMap::new();
        for t in twists {
            let j = joint_index(rig, &t.joint)?;
            twist_by_joint
                .entry(j)
                .or_default()
                .push((frame_index("twist", t.frame)?, t.angle));
        }
        // The free motion carries the twists; the held one adds the contacts on their keyed
        // frames (LoA Eq. 3 smooths a held limb like Ω(t)'s bones); `release` blends them.
        let mut free_targets = targets.clone();
        for (f, t) in free_targets.iter_mut().enumerate() {
            for (&j, ks) in &twist_by_joint {
                let angle = piecewise_linear(ks, f);
                t.twists.push(OrientTarget {
                    joint: j,
                    rotation: twist_target(rig, &worlds[f], j, angle),
                });
            }
        }
        let mut held_targets = free_targets.clone();
        for (f, t) in held_targets.iter_mut().enumerate() {
            t.contacts = contact_targets[f].clone();
            for &k in &trajectories.limbs[f] {
                if !t.bones.contains(&k) {
                    t.bones.push(k);
                }
            }
        }
        for t in &held_targets {
            for c in &t.contacts {
                mark_ancestors(rig, ChainPoint::Tip(c.joint), &mut dof);
            }
            for o in &t.twists {
                mark_ancestors(rig, ChainPoint::Tip(o.joint), &mut dof);
            }
        }
        let weights3 = super::Weights {
            regularization: weights.spatial_regularization,
            ..*weights
        };
        let axes = [DVec3::X, DVec3::Y, DVec3::Z];
        check_unknowns(
            reduction.nodes(),
            Columns::new(rig, &dof, &axes, &axes).len(),
        )?;
        let solve = |targets: &[FrameTargets], poses: &mut Poses| {
            Stage {
                rig,
                camera: &camera,
                cols: Columns::new(
                    rig,
                    &dof,
                    &[DVec3::X, DVec3::Y, DVec3::Z],
                    &[DVec3::X, DVec3::Y, DVec3::Z],
                ),
                targets,
                reduction: &reduction,
                weights: &weights3,
                ref_length,
                height,
            }
            .solve(poses, max_iterations, DEFAULT_TOLERANCE)
        };
        if !twists.is_empty() {
            spatial = Some(solve(&free_targets, &mut poses));
        }
        if !contacts.is_empty() {
            let mut held = poses.clone();
            let report = solve(&held_targets, &mut held);
            spatial = Some(match spatial {
                Some(free) => StageReport {
                    iterations: free.iterations + report.iterations,
                    initial_energy: free.initial_energy,
                    ..report
                },
                None => report,
            });
            poses = release::blend(&poses, &held, &trajectories.windows);
        }
    }

    // Output and measurements.
    let worlds = poses.worlds(rig);
    let report = measure(
        rig,
        &camera,
        &targets,
        &contact_targets,
        &worlds,
        height,
        first,
    );
    let n = rig.len();
    let mut positions = Vec::with_capacity(frames * n);
    let mut rotations = Vec::with_capacity(frames * n);
    let mut scales = Vec::with_capacity(frames * n);
    for w in &worlds {
        positions.extend_from_slice(&w.position);
        rotations.extend_from_slice(&w.rotation);
        scales.extend_from_slice(&w.scale);
    }
    let constrained = targets
        .iter()
        .map(|t| {
            t.points
                .iter()
                .map(|p| match p.point {
                    ChainPoint::Joint(j) | ChainPoint::Tip(j) => j,
                })
                .collect()
        })
        .collect();
    Ok(Motion {
        fps: line.fps,
        first_frame: first,
        joints: n,
        positions,
        rotations,
        scales,
        camera,
        plane,
        screen,
        line: lines.into_iter().map(|l| l.points).collect(),
        constrained,
        report: AnimateReport {
            planar,
            spatial,
            ..report
        },
    })
}

/// Linear interpolation of `(frame, value)` keys at `f`, held outside.
fn piecewise_linear(keys: &[(usize, f64)], f: usize) -> f64 {
    let mut ks = keys.to_vec();
    ks.sort_by_key(|k| k.0);
    match ks.iter().position(|k| k.0 >= f) {
        None => ks.last().map_or(0.0, |k| k.1),
        Some(0) => ks[0].1,
        Some(i) => {
            let ((f0, a), (f1, b)) = (ks[i - 1], ks[i]);
            a + (b - a) * (f - f0) as f64 / (f1 - f0).max(1) as f64
        }
    }
}

/// The character's distances to the line over every constrained point of every frame
/// (see [`AnimateReport`]), `first` being the first frame's number.
fn line_distances(
    rig: &Rig,
    camera: &ActionCamera,
    targets: &[FrameTargets],
    worlds: &[WorldPose],
    first: i64,
) -> AnimateReport {
    let name = |p: ChainPoint| match p {
        ChainPoint::Joint(j) => rig.names[j].clone(),
        ChainPoint::Tip(j) => format!("{} (tip)", rig.names[j]),
    };
    let mut all = Vec::new();
    let mut worst = WorstPoint::default();
    let mut measured = std::collections::BTreeSet::new();
    let mut unmeasured_frames = Vec::new();
    for ((t, w), frame) in targets.iter().zip(worlds).zip(first..) {
        if t.points.is_empty() || t.line_length <= 0.0 {
            unmeasured_frames.push(frame);
            continue;
        }
        for p in &t.points {
            let d = (camera.project(point_position(rig, w, p.point)) - p.target).length()
                / t.line_length;
            measured.insert(p.point);
            all.push(d);
            if d > worst.distance {
                worst = WorstPoint {
                    distance: d,
                    joint: name(p.point),
                    frame,
                };
            }
        }
    }
    let mean = if all.is_empty() {
        0.0
    } else {
        all.iter().sum::<f64>() / all.len() as f64
    };
    all.sort_by(f64::total_cmp);
    // Nearest rank: the smallest value with at least 95 % of the distances at or below it.
    let p95 = match all.len() {
        0 => 0.0,
        n => all[((0.95 * n as f64).ceil() as usize).clamp(1, n) - 1],
    };
    AnimateReport {
        line_distance_mean: mean,
        line_distance_p95: p95,
        line_distance_worst: worst,
        measured_joints: measured.into_iter().map(name).collect(),
        unmeasured_frames,
        ..AnimateReport::default()
    }
}

#[allow(clippy::too_many_arguments)]
fn measure(
    rig: &Rig,
    camera: &ActionCamera,
    targets: &[FrameTargets],
    contacts: &[Vec<ContactTarget>],
    worlds: &[WorldPose],
    height: f64,
    first: i64,
) -> AnimateReport {
    let mut step: f64 = 0.0;
    for pair in worlds.windows(2) {
        for j in 0..rig.len() {
            let local = |w: &WorldPose| -> DQuat {
                let p = rig.skeleton_parent[j].map_or(DQuat::IDENTITY, |p| w.rotation[p]);
                p.inverse() * w.rotation[j]
            };
            let r = log(local(&pair[1]).inverse() * local(&pair[0])).length();
            step = step.max(r);
        }
    }
    let mut contact: f64 = 0.0;
    for (cs, w) in contacts.iter().zip(worlds) {
        for c in cs {
            contact = contact.max((w.position[c.joint] - c.position).length() / height);
        }
    }
    AnimateReport {
        max_rotation_step: step,
        contact_error_max: contact,
        height,
        ..line_distances(rig, camera, targets, worlds, first)
    }
}
