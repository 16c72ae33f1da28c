//! What the server keeps between requests: the opened files, sampled clips, prepared smear
//! offsets (solved once per file and clip), the last line of action, and the jobs.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use crate::error::{ApiError, ApiResult};
use crate::files::{Clip, OpenedFile};
use crate::jobs::Jobs;
pub use crate::lock::lock;
use crate::memory::{MemoryPool, Reservation};

/// A file index and clip name.
pub type ClipKey = (usize, String);

/// The last line of action and the motion that follows it (for queries and exports).
#[derive(Debug)]
pub struct LoaSession {
    /// The file the character came from.
    pub file: usize,
    /// The keystrokes.
    pub keys: loa::Keystrokes,
    /// The keystrokes in `loa line`'s JSON layout (as exported).
    pub keys_json: String,
    /// The line (LoA Section 3), the joint motion and the character with the synthesized
    /// clip (LoA Section 4).
    pub done: loa::job::SceneMotion,
    /// The character's meshes merged, every motion frame (`GET /api/loa/motion`), shared
    /// with the answers that send it; sampled on first use when the answer sent the pose.
    pub merged: std::sync::OnceLock<Arc<anim::MeshAnimation>>,
    /// Counts the animate requests: a page asking for the motion of an older one is refused.
    pub version: u64,
}

/// A file's character prepared for the stroke path once per file (and frame rate): its rig
/// (`loa::animate::Character::from_scene`), the action camera the strokes are drawn
/// through and the vertex count the motion's memory is reserved for. Every stroke reuses
/// it; only the line, the solve and the skinning run again.
#[derive(Debug)]
pub struct LoaCharacter {
    /// The file's name in messages.
    pub label: String,
    /// The frame rate the rig was prepared at.
    pub fps: f64,
    /// The rig in its rest pose (LoA Section 4).
    pub character: loa::animate::Character,
    /// The action camera fitted to the character (`ActionCamera::front_fitted`).
    pub camera: loa::animate::ActionCamera,
    /// Vertices of the file's meshes (as `anim::sample` counts them).
    pub vertices: usize,
    /// The skin binding, once a stroke's motion showed that skinning it with the pose
    /// reproduces the core's positions (`loa_skin`): later strokes send the pose
    /// without sampling every vertex again.
    pub(crate) skin: std::sync::OnceLock<Arc<crate::loa_skin::CheckedSkin>>,
}

/// The last segmentation of the stopmo panel, its size curve and the library built from it
/// (for the curve, build, reconstruction and export requests).
#[derive(Debug)]
pub struct StopmoSession {
    /// Counts the segmentations: a curve or build of an older one is not stored.
    pub version: u64,
    /// Every part as its own animation (named after the part), the library input.
    pub parts: Arc<Vec<anim::MeshAnimation>>,
    /// The size-versus-error curve (StopShop Fig. 8) with its solved libraries.
    pub curve: Option<Arc<stopmo::SizeCurve>>,
    /// The library built from a point of the curve.
    pub built: Option<Arc<stopmo::LibraryResult>>,
}

/// The server's state, shared by every request.
#[derive(Debug)]
pub struct Studio {
    /// The files the studio reads (and no other).
    pub files: Vec<OpenedFile>,
    /// The canonical output folder (the only place it writes).
    pub out_dir: PathBuf,
    sampled: Mutex<HashMap<ClipKey, Arc<Clip>>>,
    prepared: Mutex<HashMap<ClipKey, Arc<smear::Prepared>>>,
    preparing: Mutex<()>,
    /// The last line of action.
    pub loa: Mutex<Option<LoaSession>>,
    /// The characters the stroke path prepared, by file (at the last frame rate asked for).
    pub characters: Mutex<HashMap<usize, Arc<LoaCharacter>>>,
    /// The stopmo panel's segmentation, curve and library.
    pub stopmo: Mutex<Option<StopmoSession>>,
    /// Long jobs (stopmo).
    pub jobs: Jobs,
    /// The memory the requests running at once share ([`Studio::reserve`]).
    pub memory: Arc<MemoryPool>,
}

impl Studio {
    /// A studio over opened files.
    pub fn new(files: Vec<OpenedFile>, out_dir: PathBuf) -> Studio {
        Studio {
            files,
            out_dir,
            sampled: Mutex::default(),
            prepared: Mutex::default(),
            preparing: Mutex::default(),
            loa: Mutex::default(),
            characters: Mutex::default(),
            stopmo: Mutex::default(),
            jobs: Jobs::default(),
            memory: MemoryPool::job_budget(),
        }
    }

    /// The studio with `pool` as its memory pool instead of one the size of the job budget
    /// (a test's small pool, a server sharing its machine).
    pub fn with_memory_pool(mut self, pool: Arc<MemoryPool>) -> Studio {
        self.memory = pool;
        self
    }

    /// Reserves the memory a job of file `index` estimates before it starts: held until the
    /// [`Reservation`] is dropped.
    ///
    /// # Errors
    /// 413 when `memory` is over the whole pool, 503 when the jobs running now leave no room
    /// for it ([`MemoryPool::reserve`]).
    pub fn reserve(
        &self,
        index: usize,
        memory: &anim::budget::JobMemory,
    ) -> ApiResult<Reservation> {
        self.memory.reserve(&self.file(index)?.label(), memory)
    }

    /// The opened file at `index`.
    pub fn file(&self, index: usize) -> ApiResult<&OpenedFile> {
        self.files.get(index).ok_or_else(|| {
            ApiError::not_found(format!(
                "file {index}: the studio opened {} file(s) and reads no other",
                self.files.len()
            ))
        })
    }

    /// The clip `clip` of file `index`, sampled once (until [`Studio::forget_clip`]).
    pub fn sampled(&self, index: usize, clip: &str) -> ApiResult<Arc<Clip>> {
        let key = (index, clip.to_string());
        if let Some(s) = lock(&self.sampled).get(&key) {
            return Ok(s.clone());
        }
        let file = self.file(index)?;
        let s = Arc::new(Clip::new(&file.label(), file.sample(Some(clip))?)?);
        lock(&self.sampled).insert(key, s.clone());
        Ok(s)
    }

    /// Drops the sampled clip from the cache (a request holding it keeps it until done): a
    /// stopmo segmentation's parts hold the same frames, and a large clip is not kept twice.
    pub fn forget_clip(&self, index: usize, clip: &str) {
        lock(&self.sampled).remove(&(index, clip.to_string()));
    }

    /// The smear offsets of file `index`, clip `clip`: `smear::prepare` runs once per file
    /// and clip; every later call returns the same prepared offsets.
    pub fn prepared(&self, index: usize, clip: &str) -> ApiResult<Arc<smear::Prepared>> {
        let key = (index, clip.to_string());
        let _one_at_a_time = lock(&self.preparing);
        if let Some(p) = lock(&self.prepared).get(&key) {
            return Ok(p.clone());
        }
        let sampled = self.sampled(index, clip)?;
        let label = self.file(index)?.label();
        let p = smear::prepare(sampled.sampled.clone(), &smear::PrepareOptions::default())
            .map_err(|e| {
                let over = matches!(e, smear::SmearError::OverBudget(_));
                ApiError::refused(format!("{label}: {e}"), over)
            })?;
        let p = Arc::new(p);
        lock(&self.prepared).insert(key, p.clone());
        Ok(p)
    }
}
