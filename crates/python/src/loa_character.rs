//! `toonkit.loa.save_pose`: a host's skeleton, posed, as a character file the loa crate reads
//! (`.bvh`), written by `tkio`. The Blender extension hands its armature over this way instead
//! of writing BVH itself.

use std::path::PathBuf;

use anim::{Joint, SkeletalAnimation, Skeleton, Transform};
use glam::{Mat4, Vec3};
use numpy::PyReadonlyArray2;
use pyo3::prelude::*;

use crate::errors::{io_error, value_error};

/// The skeleton of `names`/`parents` (parents first; -1 for a root) with its joints at the
/// world positions `heads` (joints × 3) and no rest rotation, one frame, as BVH: joint k's
/// `OFFSET` is its head relative to its parent's. A leaf joint named `<parent>_end` is written
/// as its parent's `End Site` (the bone's tip).
#[pyfunction(name = "loa_save_pose")]
pub(crate) fn save_pose(
    py: Python<'_>,
    path: PathBuf,
    names: Vec<String>,
    parents: Vec<i64>,
    heads: PyReadonlyArray2<'_, f64>,
) -> PyResult<PathBuf> {
    let heads = heads.as_array();
    let n = names.len();
    if parents.len() != n || heads.shape() != [n, 3] {
        return Err(value_error(format!(
            "a pose has one parent and one (x, y, z) head per joint name: {n} names, {} parents, \
             heads of shape {:?}",
            parents.len(),
            heads.shape()
        )));
    }
    let head: Vec<Vec3> = (0..n)
        .map(|k| {
            Vec3::new(
                heads[[k, 0]] as f32,
                heads[[k, 1]] as f32,
                heads[[k, 2]] as f32,
            )
        })
        .collect();
    if !head.iter().all(|h| h.is_finite()) {
        return Err(value_error(
            "a pose's joint positions must be finite numbers",
        ));
    }
    let mut joints = Vec::with_capacity(n);
    for (k, name) in names.into_iter().enumerate() {
        let parent = match parents[k] {
            p if p < 0 => None,
            p if (p as usize) < k => Some(p as usize),
            p => {
                return Err(value_error(format!(
                    "joint {name:?}: its parent {p} does not come before it"
                )))
            }
        };
        let at = parent.map_or(head[k], |p| head[k] - head[p]);
        joints.push(Joint {
            name,
            parent,
            bind_local: Transform::from_translation(at),
        });
    }
    let skeleton = Skeleton { joints };
    let world = head.iter().map(|h| Mat4::from_translation(*h)).collect();
    let motion = SkeletalAnimation::new(anim::DEFAULT_FPS, n, world)
        .map_err(|e| value_error(format!("pose: {e}")))?;
    let text =
        tkio::bvh::write(&skeleton, &motion).map_err(|e| value_error(format!("pose: {e}")))?;
    let p = path.clone();
    py.detach(move || tkio::save(&p, &tkio::Output::Text(&text)))
        .map_err(io_error)?;
    Ok(path)
}

/// The joints (names, in chain order) a bone set resolves to on the character file at `path`
/// in `pose` (`"rest"` or `"CLIP@FRAME"`): a preset (found from names or from the hierarchy)
/// or a comma-separated joint list, as `toonkit.loa.animate`'s `bones` take it (no `@FRAME`).
#[pyfunction(name = "loa_bone_chain")]
pub(crate) fn bone_chain(
    py: Python<'_>,
    path: PathBuf,
    bones: String,
    pose: String,
) -> PyResult<Vec<String>> {
    let source = path.display().to_string();
    let bad = |e: loa::animate::AnimateError| value_error(format!("{source}: {e}"));
    let set: loa::animate::BoneSet = bones.parse().map_err(bad)?;
    let pose: loa::animate::InitialPose = pose.parse().map_err(bad)?;
    let fps = f64::from(anim::DEFAULT_FPS);
    let scene = py
        .detach(|| loa::job::open_character(&path, fps))
        .map_err(crate::loa_animate::open_error)?;
    let character = loa::animate::Character::from_scene(&scene, &pose, fps).map_err(bad)?;
    let chain = character.bone_chain(&set).map_err(bad)?;
    Ok(chain
        .into_iter()
        .map(|k| character.joint_names()[k].clone())
        .collect())
}

/// `(name, label, description)` of every bone-set preset, defined once in the loa crate (the
/// Blender panel lists them from here).
pub(crate) fn bone_set_presets() -> Vec<(&'static str, &'static str, &'static str)> {
    loa::animate::Preset::ALL
        .iter()
        .map(|&(p, name)| (name, p.label(), p.description()))
        .collect()
}
