//! The files the studio was opened with (the only files it reads) and the output folder (the
//! only place it writes).

use std::ops::Range;
use std::path::{Component, Path, PathBuf};
use std::sync::OnceLock;

use anim::{Aabb, MeshAnimation, SampleOptions, SampledScene};
use rayon::prelude::*;
use tkio::{LoadOptions, Loaded};

use crate::error::{ApiError, ApiResult, StudioError};

/// Frames per second the studio samples clips at (the CLI's default).
pub const FPS: f32 = anim::DEFAULT_FPS;

/// Longest file name accepted for an export.
pub const MAX_NAME_LEN: usize = 200;

/// One opened file.
#[derive(Debug)]
pub struct OpenedFile {
    /// The path given on the command line.
    pub path: PathBuf,
    /// What was read.
    pub loaded: Loaded,
    /// The files the load read (the file, its external buffers or rest mesh): no export may
    /// replace them while the studio serves them.
    inputs: tkio::ReadScope,
}

impl OpenedFile {
    /// Reads `path` with `tkio::load`.
    pub fn open(path: &Path) -> Result<OpenedFile, StudioError> {
        let options = LoadOptions {
            fps: FPS,
            rest: None,
            ..LoadOptions::default()
        };
        let inputs = tkio::ReadScope::open();
        let loaded = tkio::load(path, &options).map_err(|e| StudioError::Open(e.to_string()))?;
        inputs.freeze();
        Ok(OpenedFile {
            path: path.to_path_buf(),
            loaded,
            inputs,
        })
    }

    /// The files the load read, each once.
    pub fn inputs(&self) -> Vec<PathBuf> {
        self.inputs.files()
    }

    /// The file name shown in the page.
    pub fn label(&self) -> String {
        self.path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| self.path.display().to_string())
    }

    /// Clip names (empty for point caches and still meshes).
    pub fn clips(&self) -> Vec<String> {
        match &self.loaded {
            Loaded::Scene(s) => s.clips.iter().map(|c| c.name.clone()).collect(),
            _ => Vec::new(),
        }
    }

    /// The scene as read, when the file is a glTF/BVH scene (a loa character).
    pub fn scene(&self) -> Option<&anim::Scene> {
        match &self.loaded {
            Loaded::Scene(s) => Some(&**s),
            _ => None,
        }
    }

    /// Samples `clip` (the first clip when `None`) at [`FPS`].
    pub fn sample(&self, clip: Option<&str>) -> ApiResult<SampledScene> {
        // A clip over the sampling budget is a request too large (413), the rest bad (400).
        let at = |e: anim::AnimError| {
            let over = matches!(e, anim::AnimError::OverBudget(_));
            ApiError::refused(format!("{}: {e}", self.label()), over)
        };
        match &self.loaded {
            Loaded::Scene(scene) => {
                let clip = match clip {
                    Some(name) if !name.is_empty() => Some(scene.find_clip(name).map_err(at)?),
                    _ => None,
                };
                let options = SampleOptions {
                    fps: FPS,
                    clip,
                    meshes: Vec::new(),
                };
                anim::sample(scene, &options).map_err(at)
            }
            Loaded::Cache(cache) => Ok(SampledScene::from_animation(cache.clone())),
            Loaded::Mesh(mesh) => Ok(SampledScene::from_animation(MeshAnimation::still(
                mesh.clone(),
            ))),
        }
    }
}

/// All mesh objects of a sampled scene as one point cache (the vertex order of every
/// per-vertex buffer the page gets).
pub fn merged(label: &str, sampled: &SampledScene) -> ApiResult<MeshAnimation> {
    if sampled.objects.is_empty() {
        return Err(ApiError::bad(format!("{label}: the file has no mesh")));
    }
    sampled.merged(label).map_err(|e| {
        let over = matches!(e, anim::AnimError::OverBudget(_));
        ApiError::refused(format!("{label}: {e}"), over)
    })
}

/// A clip sampled once, with its objects merged: a scene of one object is its own merged
/// cache (borrowed, not copied: a face of 1,440 frames is 160 MB), several are merged once.
#[derive(Debug)]
pub struct Clip {
    /// The sampled clip.
    pub sampled: SampledScene,
    /// The objects merged, when there are several.
    several: Option<MeshAnimation>,
    /// Per frame the merged vertices' bounding box, worked out on first use (the bound of a
    /// whole-clip answer of changes, docs/studio.md): not again for every restyle.
    bounds: OnceLock<Vec<Aabb>>,
    /// Per merged vertex its twin ([`Clip::twins`]), worked out on first use.
    twins: OnceLock<Vec<u32>>,
}

impl Clip {
    /// Merges the objects of `sampled` (a file without mesh is refused).
    pub fn new(label: &str, sampled: SampledScene) -> ApiResult<Clip> {
        let several = match sampled.objects.len() {
            0 => return Err(ApiError::bad(format!("{label}: the file has no mesh"))),
            1 => None,
            _ => Some(merged(label, &sampled)?),
        };
        Ok(Clip {
            sampled,
            several,
            bounds: OnceLock::new(),
            twins: OnceLock::new(),
        })
    }

    /// Every object's vertices as one cache, in object order.
    pub fn merged(&self) -> &MeshAnimation {
        match &self.several {
            Some(m) => m,
            None => &self.sampled.objects[0].animation,
        }
    }

    /// The merged animation handed over (a job that keeps only what it makes from the clip):
    /// moved out when no one else holds the clip, copied otherwise.
    pub fn into_merged(clip: std::sync::Arc<Clip>) -> MeshAnimation {
        match std::sync::Arc::try_unwrap(clip) {
            Ok(Clip {
                several: Some(m), ..
            }) => m,
            Ok(Clip { mut sampled, .. }) => sampled.objects.swap_remove(0).animation,
            Err(shared) => shared.merged().clone(),
        }
    }

    /// The diagonal of the merged vertices' bounding box over clip frames `frames` (0 for
    /// none); the boxes of the frames are found once per clip.
    pub fn diagonal(&self, frames: Range<usize>) -> f32 {
        let bounds = self.bounds.get_or_init(|| {
            let m = self.merged();
            (0..m.frame_count())
                .into_par_iter()
                .map(|f| Aabb::from_points(m.frame(f)))
                .collect()
        });
        bounds
            .get(frames)
            .and_then(|b| b.iter().copied().reduce(Aabb::union))
            .map_or(0.0, |b| b.diagonal())
    }

    /// Per merged vertex its twin: the first vertex whose positions are the same bits in every
    /// frame of the clip (itself when none is). A mesh split at its seams and hard edges holds
    /// each corner several times (the robot's 7,214 vertices are 1,820 points): a whole-clip
    /// answer of changes sends a vertex the style moved as its twin did only once
    /// (docs/studio.md, "Smear: what the style moved"). Found once per clip.
    pub fn twins(&self) -> &[u32] {
        self.twins.get_or_init(|| self.merged().twins())
    }

    /// The merged positions as float32 coordinates (for [`crate::pack::Pack::shared`]).
    pub fn coordinates(&self) -> &[f32] {
        crate::pack::coordinates(self.merged().positions())
    }
}

/// Makes (if needed) and canonicalizes the output folder.
pub fn output_folder(path: &Path) -> Result<PathBuf, StudioError> {
    let err = |source| StudioError::OutputFolder {
        path: path.display().to_string(),
        source,
    };
    std::fs::create_dir_all(path).map_err(err)?;
    path.canonicalize().map_err(err)
}

/// Where an export named `name` goes: `name` must be a relative path of plain components
/// (no `..`, no root, no drive, no hidden `.` segments), and the result stays inside
/// `folder` (the canonical output folder) even through symbolic links. Parent folders are
/// made.
pub fn output_path(folder: &Path, name: &str) -> ApiResult<PathBuf> {
    let refuse = |why: &str| ApiError::forbidden(format!("{name}: {why}"));
    if name.is_empty() || name.len() > MAX_NAME_LEN {
        return Err(refuse("give a file name (1 to 200 characters)"));
    }
    if name.contains('\\') || name.contains('\0') || name.contains(':') {
        return Err(refuse("names may not contain '\\', ':' or NUL"));
    }
    let rel = Path::new(name);
    let mut parts = 0;
    for c in rel.components() {
        match c {
            Component::Normal(s) if !s.to_string_lossy().starts_with('.') => parts += 1,
            _ => {
                return Err(refuse(
                    "outside the output folder (use a plain relative name)",
                ))
            }
        }
    }
    if parts == 0 {
        return Err(refuse("give a file name"));
    }
    let path = folder.join(rel);
    let parent = path
        .parent()
        .ok_or_else(|| refuse("outside the output folder"))?;
    std::fs::create_dir_all(parent)
        .map_err(|e| ApiError::internal(format!("{}: {e}", parent.display())))?;
    let real = parent
        .canonicalize()
        .map_err(|e| ApiError::internal(format!("{}: {e}", parent.display())))?;
    if !real.starts_with(folder) {
        return Err(refuse("outside the output folder"));
    }
    if path.is_symlink() {
        return Err(refuse("is a symbolic link"));
    }
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn export_names_stay_inside_the_folder() {
        let dir = tempfile::tempdir().unwrap();
        let folder = output_folder(dir.path()).unwrap();
        let ok = output_path(&folder, "shots/a.glb").unwrap();
        assert!(ok.starts_with(&folder) && ok.ends_with("shots/a.glb"));
        for bad in [
            "../a.glb",
            "/etc/passwd",
            "a/../../b",
            "",
            ".hidden",
            "a\\..\\b",
            "C:x",
        ] {
            let e = output_path(&folder, bad).unwrap_err();
            assert_eq!(e.status, axum::http::StatusCode::FORBIDDEN, "{bad}");
        }
    }

    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_out_of_the_folder_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let outside = tempfile::tempdir().unwrap();
        let folder = output_folder(dir.path()).unwrap();
        std::os::unix::fs::symlink(outside.path(), folder.join("link")).unwrap();
        assert!(output_path(&folder, "link/x.glb").is_err());
    }
}
