//! `prepare`: everything of a smear job that does not depend on the style — the offset solve
//! (SMEAR Eqs. 1–9) per object group, merged inside the crate, the camera, painted weights and
//! the velocities the stylization functions read.

use std::sync::{Arc, OnceLock};
use std::time::Instant;

use anim::{Camera, MeshAnimation, SampledScene};

use serde::{Deserialize, Serialize};

use crate::revolve::{replace_offsets, revolving_objects, target_arcs, Arcs};
use crate::solver::SolvedField;
use crate::velocity::CameraSpace;
use crate::{
    Collider, EffectInputs, MotionOffsets, OffsetMode, OffsetOptions, Result, SizeReference,
    SmearError, SpeedUnits, StyleUnits, SurfacePoint, WeightSource,
};

/// What [`prepare`] computes once for any number of [`stylize`](crate::stylize) calls.
///
/// Deserializes from TOML/JSON with every field optional (the defaults of
/// [`OffsetOptions`], no painted weights, objects kept apart).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PrepareOptions {
    /// Motion-offset options (SMEAR Section 3).
    pub offsets: OffsetOptions,
    /// Painted weights ω of every vertex (SMEAR Fig. 15b), resolved once (a function of the
    /// rest position reads it in size units, see [`Prepared::size`]); a style's own
    /// `weights` replace them in [`stylize`](crate::stylize).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub weights: Option<WeightSource>,
    /// Merge every object into one point cache of this name (vertex order of
    /// `anim::SampledScene::merged`, the order every per-vertex output uses); `None` keeps the
    /// objects apart, so a style can override its effects per object.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub merge: Option<String>,
    /// Objects of the scene that are collider meshes (issue #22): taken out of the scene
    /// (neither smeared nor in the results) and kept as [`Collider`]s that the elongated and
    /// multiple in-betweens of every other object never enter. More colliders (e.g. loaded
    /// from a file) join with [`Prepared::add_collider`].
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub colliders: Vec<String>,
}

/// How one object's offsets came out.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ObjectOffsets {
    /// Object name.
    pub name: String,
    /// Number of vertices.
    pub vertices: usize,
    /// How its offsets were computed.
    pub mode: OffsetMode,
    /// Smallest offset.
    pub min: f32,
    /// Largest offset.
    pub max: f32,
}

/// What [`prepare`] did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PrepareReport {
    /// Number of frames.
    pub frames: usize,
    /// Frames per second.
    pub fps: f32,
    /// Vertices over all objects.
    pub vertices: usize,
    /// Every object of the scene, in scene order.
    pub objects: Vec<ObjectOffsets>,
    /// Smallest and largest offset over all objects.
    pub range: (f32, f32),
    /// Seconds spent solving the offsets.
    pub solve_seconds: f64,
    /// Seconds spent in total.
    pub seconds: f64,
}

/// One object the effects apply to (a scene object, or all of them merged).
#[derive(Debug)]
struct Target {
    name: String,
    offsets: MotionOffsets,
    weights: Option<Vec<f32>>,
    /// Revolving parts (issue #22).
    arcs: Option<Arcs>,
    /// Per vertex its twin ([`MeshAnimation::twins`]), found on the first stylization.
    twins: OnceLock<Vec<u32>>,
}

/// A scene with its motion offsets solved, ready to be stylized any number of times
/// ([`stylize`](crate::stylize) only reads it).
#[derive(Debug)]
pub struct Prepared {
    /// Shared with the caller when it passed an `Arc` (no copy of the clip).
    scene: Arc<SampledScene>,
    options: PrepareOptions,
    field: SolvedField,
    camera: Option<Camera>,
    /// The camera's matrices per frame: velocities (speed) are differences of the positions
    /// in its space, computed where a stylization reads them (no `frames × vertices` buffer).
    space: Option<CameraSpace>,
    merged: Option<MeshAnimation>,
    targets: Vec<Target>,
    colliders: Vec<Collider>,
    report: PrepareReport,
    /// The character's size: bounding-box diagonal of every object at its rest pose.
    size: f32,
}

/// Takes the objects named in `names` out of `scene` as colliders.
///
/// # Errors
/// [`SmearError::UnknownCollider`] for a name no object has.
fn take_colliders(scene: &mut SampledScene, names: &[String]) -> Result<Vec<Collider>> {
    let mut colliders = Vec::with_capacity(names.len());
    for name in names {
        let Some(k) = scene.objects.iter().position(|o| &o.name == name) else {
            let available: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
            return Err(SmearError::UnknownCollider {
                name: name.clone(),
                available: available.join(", "),
            });
        };
        colliders.push(Collider::from_animation(&scene.objects.remove(k).animation));
    }
    Ok(colliders)
}

/// Per-object offset reports.
fn object_reports(
    scene: &SampledScene,
    mode: impl Fn(usize) -> Option<OffsetMode>,
    per_object: &[MotionOffsets],
) -> Vec<ObjectOffsets> {
    scene
        .objects
        .iter()
        .zip(per_object)
        .enumerate()
        .map(|(i, (o, d))| {
            let (min, max) = d.range();
            ObjectOffsets {
                name: o.name.clone(),
                vertices: d.vertex_count(),
                mode: mode(i).unwrap_or(OffsetMode::Simple),
                min,
                max,
            }
        })
        .collect()
}

/// Smallest and largest offset over all objects, `(0, 0)` when there are none.
fn overall_range(objects: &[ObjectOffsets]) -> (f32, f32) {
    if objects.is_empty() {
        return (0.0, 0.0);
    }
    objects
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), o| {
            (lo.min(o.min), hi.max(o.max))
        })
}

/// Motion offsets of a whole scene, merged in object order, with a report.
#[derive(Debug, Clone)]
pub struct SceneOffsets {
    /// Offsets of every vertex of every object (vertex order of
    /// `anim::SampledScene::merged`).
    pub offsets: MotionOffsets,
    /// Per-object modes and ranges, timings.
    pub report: PrepareReport,
}

/// Bytes per vertex and frame of the offsets a solve holds: raw and smoothed (f32).
const OFFSET_BYTES: u64 = 8;

/// Bytes per vertex and frame of a flipbook coloured by offset: position and RGBA (f32).
const FLIPBOOK_VERTEX_BYTES: u64 = 12 + 16;

/// Checks what a solve of `scene` will hold against [`anim::budget::DEFAULT_MAX_JOB_BYTES`]
/// before it allocates: `position_copies` copies of the clip's positions, its offsets and
/// `file_bytes` per vertex and frame of the file written.
fn check_memory(scene: &SampledScene, position_copies: u64, file_bytes: u64) -> Result<()> {
    let (frames, vertices) = (scene.frame_count, scene.vertex_count());
    anim::budget::JobMemory::new()
        .positions("copies of the clip", frames, vertices, position_copies)
        .bytes(
            "its offsets and their file",
            anim::budget::product(&[frames as u64, vertices as u64, OFFSET_BYTES + file_bytes]),
        )
        .check("lower --fps or pick a shorter clip")?;
    Ok(())
}

/// Solves the motion offsets of every object of `scene` (SMEAR Eqs. 1–9, smoothed by
/// SMEAR Eq. 2) and merges them in object order — the whole `toonkit smear offsets` job.
///
/// # Errors
/// As [`prepare`].
///
/// # Performance
/// One solve, parallel over frames; the only copy is the merge of several objects.
pub fn offsets(scene: &SampledScene, options: &OffsetOptions) -> Result<SceneOffsets> {
    let start = Instant::now();
    // The clip, its offsets and the file they are written to (at most a coloured flipbook).
    check_memory(scene, 1, FLIPBOOK_VERTEX_BYTES)?;
    let field = SolvedField::new(scene, options)?;
    let revolving = revolving_objects(scene, &options.revolve)?;
    let modes: Vec<Option<OffsetMode>> = (0..field.object_count()).map(|i| field.mode(i)).collect();
    // The field is not kept: objects alone in their group are smoothed in their raw buffer.
    let per_object = replace_offsets(scene, options, &revolving, field.into_all());
    let solve_seconds = start.elapsed().as_secs_f64();
    let objects = object_reports(scene, |i| modes.get(i).copied().flatten(), &per_object);
    let offsets = if per_object.len() == 1 {
        per_object.into_iter().next().expect("one object")
    } else {
        MotionOffsets::concat(&per_object)?
    };
    Ok(SceneOffsets {
        offsets,
        report: PrepareReport {
            frames: scene.frame_count,
            fps: scene.fps,
            vertices: scene.vertex_count(),
            range: overall_range(&objects),
            objects,
            solve_seconds,
            seconds: start.elapsed().as_secs_f64(),
        },
    })
}

/// Prepares `scene` for stylization: solves the motion offsets of every object
/// (SMEAR Eqs. 1–9, smoothed by SMEAR Eq. 2), merges them when asked, resolves the camera and the
/// painted weights, and measures the velocities (camera-relative when a camera is selected).
///
/// # Errors
/// Unknown pruned joint, camera, weight joint, attribute or collider object; an inconsistent scene; merging a
/// scene without objects.
///
/// `scene` is a `SampledScene` (moved in) or an `Arc` of one a front end keeps (shared, not
/// copied: the Python module's `Scene` and its prepared offsets hold the same clip).
///
/// # Performance
/// The offset solve dominates (parallel over frames); velocities are one pass over the
/// positions. The clip is copied only when `options.colliders` takes objects out of a
/// shared scene.
pub fn prepare(scene: impl Into<Arc<SampledScene>>, options: &PrepareOptions) -> Result<Prepared> {
    let start = Instant::now();
    let mut scene = scene.into();
    // The clip, a buffer of its size for the velocities of a stylization that reads them
    // whole ([`EffectInputs::velocities`]), a merged copy and the offsets (stylizing adds its
    // own).
    check_memory(&scene, 2 + u64::from(options.merge.is_some()), 0)?;
    let colliders = if options.colliders.is_empty() {
        Vec::new()
    } else {
        take_colliders(Arc::make_mut(&mut scene), &options.colliders)?
    };
    let scene = scene;
    let camera = options.offsets.selected_camera(&scene.cameras)?.cloned();
    let mut field = SolvedField::new(&scene, &options.offsets)?;
    let revolving = revolving_objects(&scene, &options.offsets.revolve)?;
    // The field keeps what surface points need; its raw offsets become the smoothed ones.
    let per_object = replace_offsets(&scene, &options.offsets, &revolving, field.take_all());
    let solve_seconds = start.elapsed().as_secs_f64();
    let objects = object_reports(&scene, |i| field.mode(i), &per_object);
    let size = scene.rest_diagonal();
    let weight_units = StyleUnits::size(size as f64, scene.fps as f64);
    let space = camera
        .as_ref()
        .map(|c| CameraSpace::new(c, scene.frame_count));
    let resolve = |w: &WeightSource, i: usize| w.vertex_weights_in(&scene, i, &weight_units);
    let (merged, targets) = match &options.merge {
        Some(name) => {
            if scene.objects.is_empty() {
                return Err(SmearError::InvalidScene("the scene has no mesh".into()));
            }
            let anim = scene
                .merged(name)
                .map_err(|e| SmearError::InvalidScene(e.to_string()))?;
            let weights = match &options.weights {
                Some(w) => {
                    let mut all = Vec::with_capacity(anim.vertex_count());
                    for i in 0..scene.objects.len() {
                        all.extend(resolve(w, i)?);
                    }
                    Some(all)
                }
                None => None,
            };
            let offsets = if per_object.len() == 1 {
                per_object.into_iter().next().expect("one object")
            } else {
                MotionOffsets::concat(&per_object)?
            };
            let target = Target {
                name: name.clone(),
                offsets,
                weights,
                arcs: target_arcs(&scene, &revolving, None),
                twins: OnceLock::new(),
            };
            (Some(anim), vec![target])
        }
        None => {
            let mut targets = Vec::with_capacity(scene.objects.len());
            for (i, (o, offsets)) in scene.objects.iter().zip(per_object).enumerate() {
                targets.push(Target {
                    name: o.name.clone(),
                    offsets,
                    weights: match &options.weights {
                        Some(w) => Some(resolve(w, i)?),
                        None => None,
                    },
                    arcs: target_arcs(&scene, &revolving, Some(i)),
                    twins: OnceLock::new(),
                });
            }
            (None, targets)
        }
    };
    let report = PrepareReport {
        frames: scene.frame_count,
        fps: scene.fps,
        vertices: scene.vertex_count(),
        range: overall_range(&objects),
        objects,
        solve_seconds,
        seconds: start.elapsed().as_secs_f64(),
    };
    Ok(Prepared {
        scene,
        options: options.clone(),
        field,
        camera,
        space,
        merged,
        targets,
        colliders,
        report,
        size,
    })
}

impl Prepared {
    /// The scene as sampled.
    pub fn scene(&self) -> &SampledScene {
        &self.scene
    }

    /// The collider meshes every object's in-betweens stay out of (issue #22).
    pub fn colliders(&self) -> &[Collider] {
        &self.colliders
    }

    /// Adds a collider mesh (e.g. [`Collider::from_animation`] of a file loaded with
    /// `tkio::load`): later [`stylize`](crate::stylize) calls keep every in-between out of it.
    pub fn add_collider(&mut self, collider: Collider) {
        self.colliders.push(collider);
    }

    /// Adds every mesh of `scene` (a collider file, loaded and sampled) as a collider,
    /// moving frame by frame when the scene is animated.
    ///
    /// # Errors
    /// [`SmearError::NoColliderMesh`] when the scene has no mesh.
    pub fn add_colliders(&mut self, scene: &SampledScene) -> Result<()> {
        if scene.objects.is_empty() {
            return Err(SmearError::NoColliderMesh);
        }
        for o in &scene.objects {
            self.add_collider(Collider::from_animation(&o.animation));
        }
        Ok(())
    }

    /// The options it was prepared with.
    pub fn options(&self) -> &PrepareOptions {
        &self.options
    }

    /// What preparing did (per-object offset modes and ranges, timings).
    pub fn report(&self) -> &PrepareReport {
        &self.report
    }

    /// The camera offsets and speeds are measured against (`None`: world space).
    pub fn camera(&self) -> Option<&Camera> {
        self.camera.as_ref()
    }

    /// Number of objects the effects apply to: the scene's objects, or 1 when merged.
    pub fn object_count(&self) -> usize {
        self.targets.len()
    }

    /// Name of object `i` (the merged name when merged).
    ///
    /// # Panics
    /// If `i >= object_count()`.
    pub fn name(&self, i: usize) -> &str {
        &self.targets[i].name
    }

    /// Point cache of object `i` (all objects merged when merged).
    ///
    /// # Panics
    /// If `i >= object_count()`.
    pub fn animation(&self, i: usize) -> &MeshAnimation {
        match &self.merged {
            Some(m) => m,
            None => &self.scene.objects[i].animation,
        }
    }

    /// Motion offsets of object `i`'s vertices.
    ///
    /// # Panics
    /// If `i >= object_count()`.
    pub fn offsets(&self, i: usize) -> &MotionOffsets {
        &self.targets[i].offsets
    }

    /// Arcs of object `i`'s revolving parts (issue #22), if it has any.
    ///
    /// # Panics
    /// If `i >= object_count()`.
    pub fn arcs(&self, i: usize) -> Option<&Arcs> {
        self.targets[i].arcs.as_ref()
    }

    /// Painted weights of object `i`'s vertices (from [`PrepareOptions::weights`]).
    ///
    /// # Panics
    /// If `i >= object_count()`.
    pub fn weights(&self, i: usize) -> Option<&[f32]> {
        self.targets[i].weights.as_deref()
    }

    /// Painted weights of object `i` from another source (a style's `weights`); a function
    /// of the rest position reads it in the default size units ([`Prepared::size`]).
    ///
    /// # Errors
    /// Unknown joint or attribute, or a function that does not compile.
    pub fn resolve_weights(&self, source: &WeightSource, i: usize) -> Result<Vec<f32>> {
        let units = self.units(SpeedUnits::Size, None)?;
        self.resolve_weights_in(source, i, &units)
    }

    /// [`Prepared::resolve_weights`] with the rest position of a function in `units`.
    ///
    /// # Errors
    /// As [`Prepared::resolve_weights`].
    pub fn resolve_weights_in(
        &self,
        source: &WeightSource,
        i: usize,
        units: &StyleUnits,
    ) -> Result<Vec<f32>> {
        if self.merged.is_none() {
            return source.vertex_weights_in(&self.scene, i, units);
        }
        let mut all = Vec::with_capacity(self.animation(0).vertex_count());
        for k in 0..self.scene.objects.len() {
            all.extend(source.vertex_weights_in(&self.scene, k, units)?);
        }
        Ok(all)
    }

    /// The character's size in scene units: the bounding-box diagonal of every object at
    /// its rest pose ([`SampledScene::rest_diagonal`], colliders excluded) — one size unit
    /// of a style in [`SpeedUnits::Size`] without a `size_reference`.
    pub fn size(&self) -> f32 {
        self.size
    }

    /// How a style's numbers convert into this scene's units: nothing in
    /// [`SpeedUnits::Scene`]; in [`SpeedUnits::Size`] one length unit is `reference` (a
    /// length, or an object's bounding-box diagonal at its rest pose) or
    /// [`Prepared::size`], and speeds are per second at the scene's frame rate.
    ///
    /// # Errors
    /// [`SmearError::UnknownSizeReference`] for an object name the scene does not have.
    pub fn units(
        &self,
        units: SpeedUnits,
        reference: Option<&SizeReference>,
    ) -> Result<StyleUnits> {
        let size = match (units, reference) {
            (SpeedUnits::Scene, _) => return Ok(StyleUnits::SCENE),
            (SpeedUnits::Size, None) => self.size,
            (SpeedUnits::Size, Some(SizeReference::Length(l))) => *l,
            (SpeedUnits::Size, Some(SizeReference::Node(name))) => {
                let Some(o) = self.scene.objects.iter().find(|o| &o.name == name) else {
                    let available: Vec<&str> =
                        self.scene.objects.iter().map(|o| o.name.as_str()).collect();
                    return Err(SmearError::UnknownSizeReference {
                        name: name.clone(),
                        available: available.join(", "),
                    });
                };
                o.rest_bounds.diagonal()
            }
        };
        Ok(StyleUnits::size(size as f64, self.report.fps as f64))
    }

    /// The effect inputs of object `i`'s vertices — positions, offsets, velocities borrowed
    /// from the prepared data — with painted `weights` (one per vertex) if given.
    ///
    /// # Errors
    /// [`SmearError::UnknownObject`], or weights of the wrong length.
    pub fn inputs(&self, i: usize, weights: Option<Vec<f32>>) -> Result<EffectInputs<'_>> {
        let t = self.targets.get(i).ok_or(SmearError::UnknownObject {
            index: i,
            count: self.targets.len(),
        })?;
        let causal = self.options.offsets.causal;
        let velocities = (self.space.as_ref(), causal);
        let anim = self.animation(i);
        let twins = t.twins.get_or_init(|| anim.twins());
        let inputs = EffectInputs::from_prepared(anim, &t.offsets, velocities, None)
            .with_causal(causal)
            .with_arcs(t.arcs.as_ref().map(std::borrow::Cow::Borrowed))?
            .with_colliders(&self.colliders)
            .with_twins(twins)?;
        match weights {
            Some(w) => inputs.with_weights(w),
            None => Ok(inputs),
        }
    }

    /// Offsets at surface points of object `i` (SMEAR Section 4.3: SMEAR Eq. 8 evaluated at
    /// the points' own positions with the prepared field; no solve). On a merged object the
    /// points must be sorted by triangle (they are split by source object).
    ///
    /// # Errors
    /// [`SmearError::UnknownObject`], or [`SmearError::InvalidSurfacePoint`].
    pub fn surface_offsets(&self, i: usize, points: &[SurfacePoint]) -> Result<MotionOffsets> {
        let objects: Vec<&MeshAnimation> =
            self.scene.objects.iter().map(|o| &o.animation).collect();
        if self.merged.is_none() {
            return self.field.surface_offsets(&objects, i, points);
        }
        if i != 0 {
            return Err(SmearError::UnknownObject { index: i, count: 1 });
        }
        let mut parts = Vec::with_capacity(objects.len());
        let (mut base, mut k) = (0u32, 0usize);
        for (o, anim) in objects.iter().enumerate() {
            let end = base + anim.mesh.triangles.len() as u32;
            let local: Vec<SurfacePoint> = points[k..]
                .iter()
                .take_while(|s| s.triangle < end)
                .map(|s| SurfacePoint {
                    triangle: s.triangle - base,
                    ..*s
                })
                .collect();
            k += local.len();
            parts.push(self.field.surface_offsets(&objects, o, &local)?);
            base = end;
        }
        if k < points.len() {
            return Err(SmearError::InvalidSurfacePoint {
                index: k,
                reason: format!(
                    "triangle {} is out of order or does not exist (sort the points by triangle)",
                    points[k].triangle
                ),
            });
        }
        MotionOffsets::concat(&parts)
    }
}
