//! BVH writing: a skeleton and its per-frame pose → BVH text with `ZXY` rotation channels.
//!
//! BVH has no rest rotations and no scale: every joint's frame is its parent's frame moved by a
//! constant `OFFSET` and turned by the channel rotation. The writer therefore works from world
//! matrices: each joint's world rotation (scale removed) and world position are what a reader
//! reproduces. Offsets are taken from the bind pose, in the parent's world-rotation frame, so
//! scale anywhere in the chain is baked into the offsets. Joints whose distance to their parent
//! changes during the motion (beyond [`DEFAULT_POSITION_TOLERANCE`]) also get position
//! channels (reader convention: position = `OFFSET` + channel value). Roots always have
//! position channels and `OFFSET 0 0 0`, so tools that read root positions as absolute agree.
//!
//! A leaf joint named `<parent>_end` (as [`super::read`] names `End Site`s) is written back as
//! an `End Site`; any other leaf gets an `End Site` on its local +Y axis at the parent bone's
//! length (the SPEC.md bone-tip rule), which a reader will show as an extra `<leaf>_end` node.

use std::fmt::Write as _;

use anim::{bones, SkeletalAnimation, Skeleton};
use glam::{DQuat, DVec3, EulerRot, Mat4, Quat, Vec3};

use crate::{IoError, Result};

/// Relative tolerance (× the bind skeleton's bounding-box diagonal) above which a change of a
/// joint's distance to its parent gets position channels.
pub const DEFAULT_POSITION_TOLERANCE: f32 = 1e-5;

/// Writes a sampled skeletal animation as BVH.
///
/// # Arguments
/// * `skeleton` – joints in parent-first order; `bind_local` gives the rest pose (offsets).
/// * `motion` – world matrices of every joint per frame; `Frame Time` = `1 / motion.fps`.
///
/// # Returns
/// BVH text; [`super::read`] of it gives the same world joint positions (within float
/// rounding) for every frame.
///
/// # Errors
/// [`IoError::Unsupported`] for an empty or misordered skeleton, a joint count different from
/// the motion's, or a non-positive frame rate.
pub fn write(skeleton: &Skeleton, motion: &SkeletalAnimation) -> Result<String> {
    if motion.joint_count() != skeleton.len() {
        return Err(IoError::unsupported(format!(
            "skeleton has {} joints but the motion has {}",
            skeleton.len(),
            motion.joint_count()
        )));
    }
    let world: Vec<Mat4> = (0..motion.frame_count())
        .flat_map(|f| motion.frame(f).to_vec())
        .collect();
    write_world(skeleton, &world, motion.fps)
}

/// Writes BVH from per-frame local joint rotations and root translations (the form the loa
/// tool produces).
///
/// # Arguments
/// * `skeleton` – joints in parent-first order; non-root joints keep their
///   `bind_local` translation and scale.
/// * `root_translations` – frames × (root joints, in joint order) local translations.
/// * `local_rotations` – frames × joints local rotations.
/// * `fps` – frames per second (`Frame Time = 1 / fps`).
///
/// # Errors
/// As [`write()`], plus buffer lengths that do not match the skeleton, or non-finite values.
pub fn write_local(
    skeleton: &Skeleton,
    root_translations: &[Vec3],
    local_rotations: &[Quat],
    fps: f32,
) -> Result<String> {
    let n = skeleton.len();
    let roots: Vec<usize> = (0..n)
        .filter(|&k| skeleton.joints[k].parent.is_none())
        .collect();
    if n == 0 || !local_rotations.len().is_multiple_of(n) {
        return Err(IoError::unsupported(format!(
            "{} local rotations are not a whole number of frames of {n} joints",
            local_rotations.len()
        )));
    }
    let frames = local_rotations.len() / n;
    if root_translations.len() != frames * roots.len() {
        return Err(IoError::unsupported(format!(
            "expected {} root translations ({frames} frames × {} roots), got {}",
            frames * roots.len(),
            roots.len(),
            root_translations.len()
        )));
    }
    skeleton.validate()?;
    let mut world = Vec::with_capacity(frames * n);
    let mut locals = vec![Mat4::IDENTITY; n];
    for f in 0..frames {
        let mut r = 0;
        for (k, j) in skeleton.joints.iter().enumerate() {
            let t = if j.parent.is_none() {
                r += 1;
                root_translations[f * roots.len() + r - 1]
            } else {
                j.bind_local.translation
            };
            let q = local_rotations[f * n + k].normalize();
            locals[k] = Mat4::from_scale_rotation_translation(j.bind_local.scale, q, t);
        }
        world.extend(skeleton.world_from_local(&locals));
    }
    write_world(skeleton, &world, fps)
}

fn write_world(skeleton: &Skeleton, world: &[Mat4], fps: f32) -> Result<String> {
    let n = skeleton.len();
    skeleton.validate()?;
    if n == 0 {
        return Err(IoError::unsupported("cannot write a BVH without joints"));
    }
    if !(fps.is_finite() && fps > 0.0) {
        return Err(IoError::unsupported(format!(
            "frame rate must be positive, got {fps}"
        )));
    }
    if !world.iter().all(|m| m.is_finite()) {
        return Err(IoError::unsupported(
            "joint transforms contain NaN or infinity",
        ));
    }
    let frames = world.len() / n;
    // A joint scaled to zero (a common way to hide bones) has no rotation: use the identity.
    let split = |m: &Mat4| {
        let (_, r, t) = m.as_dmat4().to_scale_rotation_translation();
        let ok = r.is_finite() && r.length_squared() > 1e-12;
        let r = if ok { r.normalize() } else { DQuat::IDENTITY };
        (r, t)
    };
    let bind: Vec<(DQuat, DVec3)> = skeleton.bind_world().iter().map(split).collect();
    let pose: Vec<(DQuat, DVec3)> = world.iter().map(split).collect();
    let parent = |k: usize| skeleton.joints[k].parent;
    let rel = |pose: &[(DQuat, DVec3)], k: usize| match parent(k) {
        Some(p) => pose[p].0.inverse() * (pose[k].1 - pose[p].1),
        None => pose[k].1,
    };
    let offsets: Vec<DVec3> = (0..n)
        .map(|k| {
            if parent(k).is_some() {
                rel(&bind, k)
            } else {
                DVec3::ZERO
            }
        })
        .collect();
    let bind_world: Vec<Mat4> = skeleton.bind_world();
    let size = anim::Aabb::from_points(
        &bind_world
            .iter()
            .map(|m| m.w_axis.truncate())
            .collect::<Vec<_>>(),
    )
    .diagonal() as f64;
    let tol = DEFAULT_POSITION_TOLERANCE as f64 * size.max(1e-6);
    let has_pos: Vec<bool> = (0..n)
        .map(|k| {
            parent(k).is_none()
                || (0..frames)
                    .any(|f| (rel(&pose[f * n..(f + 1) * n], k) - offsets[k]).length() > tol)
        })
        .collect();
    let children = skeleton.children();
    let end_site: Vec<bool> = (0..n)
        .map(|k| match parent(k) {
            Some(p) if children[k].is_empty() && !has_pos[k] => skeleton.joints[k]
                .name
                .strip_prefix(&format!(
                    "{}{}",
                    skeleton.joints[p].name,
                    super::END_SITE_SUFFIX
                ))
                .is_some_and(|rest| rest.bytes().all(|b| b.is_ascii_digit())),
            _ => false,
        })
        .collect();
    let mut bind_bones = Vec::new();
    bones(skeleton, &children, &bind_world, &mut bind_bones);

    // Hierarchy, depth-first in joint order; remember the output order for the motion.
    let mut out = String::from("HIERARCHY\n");
    let mut order = Vec::with_capacity(n);
    enum Step {
        Open(usize, usize),
        Close(usize),
    }
    let mut stack: Vec<Step> = (0..n)
        .rev()
        .filter(|&k| parent(k).is_none())
        .map(|k| Step::Open(k, 0))
        .collect();
    while let Some(step) = stack.pop() {
        match step {
            Step::Close(d) => {
                let _ = writeln!(out, "{}}}", indent(d));
            }
            Step::Open(k, d) if end_site[k] => {
                let o = offsets[k];
                let _ = writeln!(
                    out,
                    "{0}End Site\n{0}{{\n{0}  OFFSET {1}\n{0}}}",
                    indent(d),
                    vec3(o)
                );
            }
            Step::Open(k, d) => {
                let kind = if d == 0 { "ROOT" } else { "JOINT" };
                let _ = writeln!(out, "{}{kind} {}", indent(d), joint_name(skeleton, k));
                let _ = writeln!(out, "{}{{", indent(d));
                let _ = writeln!(out, "{}  OFFSET {}", indent(d), vec3(offsets[k]));
                let chans = if has_pos[k] {
                    "6 Xposition Yposition Zposition Zrotation Xrotation Yrotation"
                } else {
                    "3 Zrotation Xrotation Yrotation"
                };
                let _ = writeln!(out, "{}  CHANNELS {chans}", indent(d));
                order.push(k);
                stack.push(Step::Close(d));
                if children[k].is_empty() {
                    let len = parent(k).map_or(0.0, |p| bind_bones[p].length()) as f64;
                    let tip = DVec3::new(0.0, len, 0.0);
                    let _ = writeln!(
                        out,
                        "{0}End Site\n{0}{{\n{0}  OFFSET {1}\n{0}}}",
                        indent(d + 1),
                        vec3(tip)
                    );
                }
                for &c in children[k].iter().rev() {
                    stack.push(Step::Open(c, d + 1));
                }
            }
        }
    }

    let _ = write!(
        out,
        "MOTION\nFrames: {frames}\nFrame Time: {}\n",
        1.0 / fps as f64
    );
    let mut prev = vec![DVec3::ZERO; n];
    for f in 0..frames {
        let p = &pose[f * n..(f + 1) * n];
        let mut sep = "";
        for &k in &order {
            if has_pos[k] {
                let d = rel(p, k) - offsets[k];
                let _ = write!(out, "{sep}{}", vec3(d));
                sep = " ";
            }
            let local = match parent(k) {
                Some(q) => p[q].0.inverse() * p[k].0,
                None => p[k].0,
            };
            let (z, x, y) = local.normalize().to_euler(EulerRot::ZXY);
            let mut e = DVec3::new(z, x, y) * (180.0 / std::f64::consts::PI);
            if f > 0 {
                // Unwrap each angle to the turn nearest the previous frame's.
                e += ((prev[k] - e) / 360.0).round() * 360.0;
            }
            prev[k] = e;
            let _ = write!(out, "{sep}{} {} {}", angle(e.x), angle(e.y), angle(e.z));
            sep = " ";
        }
        out.push('\n');
    }
    Ok(out)
}

fn indent(d: usize) -> String {
    "  ".repeat(d)
}

fn joint_name(skeleton: &Skeleton, k: usize) -> String {
    let name: String = skeleton.joints[k]
        .name
        .chars()
        .map(|c| {
            if c.is_whitespace() || c == '{' || c == '}' {
                '_'
            } else {
                c
            }
        })
        .collect();
    if name.is_empty() {
        format!("joint{k}")
    } else {
        name
    }
}

fn vec3(v: DVec3) -> String {
    format!("{} {} {}", v.x as f32, v.y as f32, v.z as f32)
}

/// Degrees with 6 decimals, trailing zeros trimmed.
fn angle(v: f64) -> String {
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" || s.is_empty() {
        "0".to_string()
    } else {
        s.to_string()
    }
}
