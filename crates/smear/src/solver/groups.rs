//! How a scene's objects are grouped for the solve and where each sits in its group's
//! buffers: a character's meshes side by side, a simple object on its own.

use anim::{Aabb, MeshAnimation, SampledScene};
use glam::Vec3;

use crate::field::{Field, Tolerances};
use crate::velocity::CameraSpace;
use crate::{
    Result, SmearError, DEFAULT_STILL_TOLERANCE, DEFAULT_ZERO_LENGTH, STILL_ROUNDING_FACTOR,
};

use super::OffsetMode;

/// Where an object's vertices sit in its group.
#[derive(Debug, Clone)]
pub(super) struct Slot {
    pub(super) group: usize,
    pub(super) base: usize,
    pub(super) vertices: usize,
}

/// The positions a group's field was computed on: one object's own cache (not copied), or
/// several objects side by side.
#[derive(Debug, Clone)]
pub(super) enum GroupPositions {
    /// The cache of this object (index into the solver's objects).
    Object(usize),
    /// Frame-major positions of several objects merged.
    Merged(Vec<Vec3>),
}

#[derive(Debug)]
pub(super) struct Group {
    pub(super) positions: GroupPositions,
    pub(super) vertices: usize,
    pub(super) mode: OffsetMode,
    pub(super) field: Field,
    /// Unsmoothed vertex offsets, frame-major.
    pub(super) raw: Vec<f32>,
}

/// Absolute tolerances from the bounding box of the first, middle and last frames.
///
/// The still tolerance is SPEC.md's `DEFAULT_STILL_TOLERANCE × diagonal`, raised to the f32
/// rounding of the coordinates involved ([`STILL_ROUNDING_FACTOR`] × the largest absolute
/// coordinate, camera translation included): below that a "velocity" is rounding noise
/// (e.g. an object followed by the camera) and would give a random separation plane.
pub(super) fn tolerances(
    positions: &[Vec3],
    frames: usize,
    vertices: usize,
    space: Option<&CameraSpace>,
    causal: bool,
) -> Tolerances {
    let mut b = Aabb::EMPTY;
    if vertices > 0 {
        // Causal mode: frame 0 only, so no threshold depends on later frames.
        let probes = if causal {
            [0, 0, 0]
        } else {
            [0, frames / 2, frames.saturating_sub(1)]
        };
        for f in probes {
            b = b.union(Aabb::from_points(
                &positions[f * vertices..(f + 1) * vertices],
            ));
        }
    }
    let diag = b.diagonal();
    let mut scale = if b.is_empty() {
        0.0
    } else {
        b.min.abs().max(b.max.abs()).max_element()
    };
    if let Some(c) = space {
        scale = scale.max(c.max_translation());
    }
    Tolerances {
        still: (DEFAULT_STILL_TOLERANCE * diag).max(STILL_ROUNDING_FACTOR * scale),
        zero_length: DEFAULT_ZERO_LENGTH * diag,
        causal,
    }
}

/// Frame-major positions of several caches side by side (`None` when there is one: its own
/// cache is used as is).
pub(super) fn merged_positions(parts: &[&MeshAnimation], frames: usize) -> Option<Vec<Vec3>> {
    if parts.len() == 1 {
        return None;
    }
    let n: usize = parts.iter().map(|a| a.vertex_count()).sum();
    let mut out = Vec::with_capacity(n * frames);
    for f in 0..frames {
        for a in parts {
            out.extend_from_slice(a.frame(f));
        }
    }
    Some(out)
}

pub(super) fn merged_triangles(parts: &[&MeshAnimation]) -> Vec<[u32; 3]> {
    let mut base = 0u32;
    let mut out = Vec::new();
    for a in parts {
        out.extend(a.mesh.triangles.iter().map(|t| t.map(|i| i + base)));
        base += a.vertex_count() as u32;
    }
    out
}

/// Checks that the scene's buffers agree (bones per frame, frames per object, skin slots).
pub(super) fn check_scene(scene: &SampledScene) -> Result<()> {
    let frames = scene.frame_count;
    let joints = scene.skeleton.len();
    if joints > 0 && scene.bones.len() != frames * joints {
        return Err(SmearError::InvalidScene(format!(
            "{} bones for {frames} frames × {joints} joints",
            scene.bones.len()
        )));
    }
    for o in &scene.objects {
        if o.animation.frame_count() != frames {
            return Err(SmearError::InvalidScene(format!(
                "object '{}' has {} frames, the scene {frames}",
                o.name,
                o.animation.frame_count()
            )));
        }
        if let Some(s) = &o.skin {
            s.validate(o.animation.vertex_count(), joints)
                .map_err(|e| SmearError::InvalidScene(format!("object '{}': {e}", o.name)))?;
        }
    }
    Ok(())
}

/// Objects grouped for the solve: `Some(root joint)` for characters, `None` for a standalone
/// simple object, with the members of each group in scene order.
pub(super) fn group_keys(
    scene: &SampledScene,
    whole_body: bool,
) -> Vec<(Option<usize>, Vec<usize>)> {
    let joints = scene.skeleton.len();
    let root_of = |mut j: usize| {
        while let Some(p) = scene.skeleton.joints[j].parent {
            j = p;
        }
        j
    };
    let mut keys: Vec<(Option<usize>, Vec<usize>)> = Vec::new();
    for (i, o) in scene.objects.iter().enumerate() {
        let skin_root = o
            .skin
            .as_ref()
            .and_then(|s| s.joints.first())
            .map(|&j| root_of(j));
        let key = match (skin_root, o.parent_joint) {
            (Some(r), _) => Some(r),
            (None, Some(j)) if whole_body && j < joints => Some(root_of(j)),
            _ => None,
        };
        match keys.iter_mut().find(|(k, _)| key.is_some() && *k == key) {
            Some((_, members)) => members.push(i),
            None => keys.push((key, vec![i])),
        }
    }
    keys
}
