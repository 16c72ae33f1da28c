//! Several scenes in one glTF file: one is read (`--scene NAME|INDEX`, default the file's
//! `scene`, else the first). Nodes outside it keep their place in the hierarchy (so clip
//! channels and skins stay valid) but lose their mesh, camera and skin, so nothing of the
//! other scenes is sampled or drawn.

use anim::Scene;

use crate::{IoError, Result};

/// Restricts `scene` to one of `doc`'s scenes when the file has several or `choice` is given.
/// Returns a note naming the scene read.
///
/// # Errors
/// When `choice` names no scene of the file.
pub(crate) fn select(
    doc: &gltf::Document,
    scene: &mut Scene,
    choice: Option<&str>,
) -> Result<Option<String>> {
    let count = doc.scenes().count();
    if count < 2 && choice.is_none() {
        return Ok(None);
    }
    let label = |s: &gltf::Scene| match s.name() {
        Some(n) => format!("{} '{n}'", s.index()),
        None => s.index().to_string(),
    };
    let picked = match choice {
        Some(c) => doc
            .scenes()
            .find(|s| s.name() == Some(c) || s.index().to_string() == c)
            .ok_or_else(|| {
                let names: Vec<String> = doc.scenes().map(|s| label(&s)).collect();
                IoError::unsupported(format!(
                    "no scene {c:?} in the file (scenes: {})",
                    if names.is_empty() {
                        "none".to_string()
                    } else {
                        names.join(", ")
                    }
                ))
            })?,
        None => match doc.default_scene().or_else(|| doc.scenes().next()) {
            Some(s) => s,
            None => return Ok(None),
        },
    };
    let mut keep = vec![false; scene.nodes.len()];
    let mut stack: Vec<usize> = picked.nodes().map(|n| n.index()).collect();
    while let Some(n) = stack.pop() {
        if n < keep.len() && !keep[n] {
            keep[n] = true;
            stack.extend(scene.nodes[n].children.iter().copied());
        }
    }
    for (node, kept) in scene.nodes.iter_mut().zip(keep) {
        if !kept {
            node.mesh = None;
            node.camera = None;
            node.skin = None;
        }
    }
    Ok(Some(format!(
        "{count} scene(s); read scene {} (pick another with --scene)",
        label(&picked)
    )))
}
