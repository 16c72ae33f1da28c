//! The segmentation job: seeds or automatic parts → [`Segmentation`] → one animation per
//! part, with the report of SPEC "Output layouts" and the Fig. 5 figure.

use std::borrow::Cow;
use std::time::Instant;

use anim::MeshAnimation;
use serde::Serialize;

use super::error::{Error, Result};
use super::options::SegmentJobOptions;
use crate::segment::{HomogenizeStats, Part, SavedSegmentation, SegmentReport, Segmentation};

/// The result of [`segment`]: the segmentation, its parts, and what the job measured.
#[derive(Debug, Clone)]
pub struct Segmented {
    /// The cut (and homogenized) animation with its labels, seams and measurements.
    pub segmentation: Segmentation,
    /// Every part as its own animation, in part order, named after the part.
    pub parts: Vec<Part>,
    /// StopShop Fig. 5 as PNG bytes, when [`SegmentJobOptions::figure`] asked for it.
    pub figure: Option<Vec<u8>>,
    /// What another clip of the same mesh needs to reuse this cut
    /// ([`SegmentJobOptions::reuse`]); `"reuse"` in `segmentation.json`.
    pub saved: SavedSegmentation,
    /// Wall time of the job in seconds.
    pub seconds: f64,
}

/// One part in a [`SegmentSummary`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PartSummary {
    /// Part name.
    pub name: String,
    /// Vertices of the part (seam vertices are in every part they bound).
    pub vertices: usize,
    /// Triangles of the part.
    pub triangles: usize,
}

/// A short machine-readable summary of a segmentation (what `toonkit stopmo segment --json`
/// prints, without paths and timing).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SegmentSummary {
    /// The parts.
    pub parts: Vec<PartSummary>,
    /// Frames of the animation.
    pub frames: usize,
    /// γ used (StopShop Eq. 1).
    pub gamma: f64,
    /// Length of the part boundaries on the average mesh (model units).
    pub cut_length: f64,
    /// Number of seam vertices.
    pub seam_vertices: usize,
    /// Homogenization measurements, `null` when not run.
    pub homogenization: Option<HomogenizeStats>,
}

/// What segmenting `anim` will hold: the input, its cut copy, the parts and the file they
/// are written to ([`check_segment_memory`] checks it; a server reserves it).
pub fn segment_memory(anim: &MeshAnimation) -> anim::budget::JobMemory {
    anim::budget::JobMemory::new().positions(
        "copies of the clip (input, cut, parts, written)",
        anim.frame_count(),
        anim.vertex_count(),
        4,
    )
}

/// Checks what segmenting `anim` will hold — the input, its cut copy, the parts and the file
/// they are written to — against [`anim::budget::DEFAULT_MAX_JOB_BYTES`]; [`segment`] does
/// it first, a front end that runs [`segment`] in the background does it before starting.
///
/// # Errors
/// [`Error::Anim`] ([`anim::AnimError::OverBudget`]) naming the copies and the limit.
pub fn check_segment_memory(anim: &MeshAnimation) -> Result<()> {
    segment_memory(anim)
        .check("lower --fps or pick a shorter clip")
        .map_err(anim::AnimError::from)?;
    Ok(())
}

/// Segments `anim` into parts and homogenizes the seams (StopShop Sections 3.1–3.2): the
/// whole job of `toonkit stopmo segment`.
///
/// # Errors
/// [`Error::Option`] (`parts`) when fewer than two parts are given, [`Error::Anim`] when
/// the clip's copies would be over [`anim::budget::DEFAULT_MAX_JOB_BYTES`], or the
/// segmentation's own errors ([`Error::Segment`]).
pub fn segment(anim: &MeshAnimation, opts: &SegmentJobOptions) -> Result<Segmented> {
    segment_input(Cow::Borrowed(anim), opts, false)
}

/// [`segment`] of an animation handed over: the same result, but the input's frames become
/// the cut animation's instead of being copied, so the clip is held once less at the peak
/// (a front end that keeps only the parts gives its clip away).
///
/// # Errors
/// As [`segment`].
pub fn segment_owned(anim: MeshAnimation, opts: &SegmentJobOptions) -> Result<Segmented> {
    segment_input(Cow::Owned(anim), opts, false)
}

/// [`segment_owned`] for a front end that keeps only the parts: the input's frames become
/// the cut's, and the cut's move into the parts ([`Segmentation::take_parts`]), so the clip
/// is resident about once at the peak. The result's `segmentation.animation` then holds
/// only the cut mesh (one frame); everything else is as [`segment`] gives it.
///
/// # Errors
/// As [`segment`].
pub fn segment_into_parts(anim: MeshAnimation, opts: &SegmentJobOptions) -> Result<Segmented> {
    segment_input(Cow::Owned(anim), opts, true)
}

fn segment_input(
    anim: Cow<'_, MeshAnimation>,
    opts: &SegmentJobOptions,
    take: bool,
) -> Result<Segmented> {
    let start = Instant::now();
    check_segment_memory(&anim)?;
    let (input_vertices, input_triangles) = (anim.vertex_count(), anim.mesh.triangle_count());
    let segmentation = match &opts.reuse {
        Some(saved) => crate::segment::reuse_input(anim, saved, &opts.segment)?,
        None => {
            let parts = match opts.auto_parts {
                Some(n) => crate::segment::auto_parts(&anim, n)?,
                None => opts.parts.clone(),
            };
            if parts.len() < 2 {
                return Err(Error::option_error(
                    "parts",
                    "give at least two parts, each with a seed (or auto_parts = N)",
                ));
            }
            crate::segment::segment_input(anim, &parts, &opts.segment)?
        }
    };
    segmentation.check_parts()?;
    let mut segmentation = segmentation;
    let saved = segmentation.saved(input_vertices, input_triangles);
    let figure = if opts.figure {
        Some(render::encode_png(&super::figure::parts_figure(
            &segmentation,
        )?)?)
    } else {
        None
    };
    let parts = if take {
        segmentation.take_parts()?
    } else {
        segmentation.parts()?
    };
    Ok(Segmented {
        segmentation,
        parts,
        figure,
        saved,
        seconds: start.elapsed().as_secs_f64(),
    })
}

impl Segmented {
    /// The report of SPEC "Output layouts" (`parts`, `triangle_part`, `seam_vertices`,
    /// `gamma`, `cut_length`, `homogenization`).
    pub fn report(&self) -> SegmentReport {
        self.segmentation.report()
    }

    /// [`Segmented::report`] with the reusable segmentation under `"reuse"`, as
    /// pretty-printed JSON (`segmentation.json`).
    pub fn report_json(&self) -> String {
        let mut value = serde_json::to_value(self.report()).unwrap_or_default();
        if let (Some(map), Ok(reuse)) = (value.as_object_mut(), serde_json::to_value(&self.saved)) {
            map.insert("reuse".into(), reuse);
        }
        to_pretty_json(&value)
    }

    /// The part animations, as a [`crate::library()`] input.
    pub fn part_animations(&self) -> Vec<&MeshAnimation> {
        self.parts.iter().map(|p| &p.animation).collect()
    }

    /// Frames of the clip (the parts', which hold them all whichever job made them).
    fn frame_count(&self) -> usize {
        self.parts.first().map_or_else(
            || self.segmentation.animation.frame_count(),
            |p| p.animation.frame_count(),
        )
    }

    /// A short summary (no paths, no timing).
    pub fn summary(&self) -> SegmentSummary {
        let s = &self.segmentation;
        SegmentSummary {
            parts: self
                .parts
                .iter()
                .map(|p| PartSummary {
                    name: p.name.clone(),
                    vertices: p.animation.vertex_count(),
                    triangles: p.animation.mesh.triangle_count(),
                })
                .collect(),
            frames: self.frame_count(),
            gamma: s.gamma,
            cut_length: s.cut_length,
            seam_vertices: s.seam_vertices.len(),
            homogenization: s.homogenization,
        }
    }

    /// The seams: edges of the cut mesh ([`Segmentation::animation`]) that bound triangles of
    /// two different parts, as vertex pairs of that mesh (sorted, each edge once). Vertices
    /// that the cut duplicated are matched by their welded class, so an edge counts once
    /// whichever copy its triangles use. Front ends draw them over the face; every vertex
    /// is placed from the input by [`CutMesh::sources`](crate::segment::CutMesh::sources).
    pub fn seam_edges(&self) -> Vec<[u32; 2]> {
        let s = &self.segmentation;
        let class = &s.cut.weld_class;
        let key = |v: u32| class.get(v as usize).copied().unwrap_or(v);
        // welded edge → (a vertex pair, the first part seen, whether another part shares it)
        let mut edges: std::collections::BTreeMap<(u32, u32), ([u32; 2], u32, bool)> =
            std::collections::BTreeMap::new();
        for (t, part) in s.animation.mesh.triangles.iter().zip(&s.triangle_part) {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let (ka, kb) = (key(a), key(b));
                let welded = (ka.min(kb), ka.max(kb));
                let pair = if ka <= kb { [a, b] } else { [b, a] };
                edges
                    .entry(welded)
                    .and_modify(|e| e.2 |= e.1 != *part)
                    .or_insert((pair, *part, false));
            }
        }
        edges.into_values().filter(|e| e.2).map(|e| e.0).collect()
    }

    /// One line for people: `upper (N triangles), lower (M triangles) over F frames, cut
    /// length L, K seam vertices`.
    pub fn describe(&self) -> String {
        let names: Vec<String> = self
            .parts
            .iter()
            .map(|p| {
                format!(
                    "{} ({} triangles)",
                    p.name,
                    p.animation.mesh.triangle_count()
                )
            })
            .collect();
        format!(
            "{} over {} frames, cut length {:.3}, {} seam vertices",
            names.join(", "),
            self.frame_count(),
            self.segmentation.cut_length,
            self.segmentation.seam_vertices.len(),
        )
    }
}

/// Pretty JSON through [`serde_json::Value`] (keys sorted, numbers as serde_json prints
/// them), the form every toonkit report uses.
pub(crate) fn to_pretty_json<T: Serialize>(value: &T) -> String {
    serde_json::to_value(value)
        .and_then(|v| serde_json::to_string_pretty(&v))
        .unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
}

/// The reusable segmentation of a `segmentation.json` (its `"reuse"` section), for
/// [`SegmentJobOptions::reuse`].
///
/// # Errors
/// [`Error::Option`] (`reuse`) when the text is not JSON or has no valid `"reuse"` section.
pub fn saved_segmentation(json: &str) -> Result<SavedSegmentation> {
    let value: serde_json::Value = serde_json::from_str(json)
        .map_err(|e| Error::option_error("reuse", format!("not JSON: {e}")))?;
    let reuse = value.get("reuse").ok_or_else(|| {
        Error::option_error(
            "reuse",
            "no \"reuse\" section; write it with `stopmo segment --report` or `stopmo run`",
        )
    })?;
    serde_json::from_value(reuse.clone())
        .map_err(|e| Error::option_error("reuse", format!("bad \"reuse\" section: {e}")))
}
