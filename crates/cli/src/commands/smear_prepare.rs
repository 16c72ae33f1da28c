//! What every `toonkit smear elongate | multiples | lines` command shares: the input and output
//! arguments, the motion-offset options, the frame step, painted weights, and the prepared
//! inputs (offsets, camera-relative speed, weights, motion-line seeds).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anim::{Camera, MeshAnimation, SampledScene};
use anyhow::{bail, Result};
use clap::Args;
use smear::{
    EffectInputs, FunctionSpec, MotionOffsets, OffsetSolver, Stage, SurfacePoint, WeightAttribute,
    WeightGroup, WeightSource,
};

use super::smear::OffsetArgs;
use crate::input::{self, InputArgs};

/// Input and output of an effect command.
#[derive(Debug, Args)]
pub struct EffectIo {
    /// Input animation (glTF/GLB with skins, OBJ sequence, PC2/MDD + rest OBJ).
    pub input: PathBuf,
    /// Output file (see the command's description for the formats).
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub input_args: InputArgs,
}

/// Options of every effect: the motion-offset options of `toonkit smear offsets`, the frame
/// step and painted weights.
#[derive(Debug, Clone, Args)]
pub struct EffectArgs {
    #[command(flatten)]
    pub offsets: OffsetArgs,
    /// Frame step: 2 = "on twos" (displacements scaled by 2, drawings held two frames).
    #[arg(long, default_value_t = smear::DEFAULT_FRAME_STEP)]
    pub step: usize,
    /// Painted weights ω from a weight group (Fig. 15b): the skin weights of these joints and
    /// of every joint below them (comma-separated, case-sensitive). Presets are multiplied by
    /// ω; expressions read it as `weight`.
    #[arg(long, value_delimiter = ',', conflicts_with_all = ["weight_attribute", "weight_expr"])]
    pub weight_group: Vec<String>,
    /// With --weight-group: only the named joints, not their descendants.
    #[arg(long, requires = "weight_group")]
    pub weight_group_only: bool,
    /// Painted weights ω from a scalar vertex attribute painted in the animation package
    /// (glTF `_NAME`, e.g. `_SMEAR_WEIGHT`) or a vertex-colour channel (`COLOR_0.r`, `.g`,
    /// `.b`, `.a`), clamped to [0, 1].
    #[arg(long, conflicts_with = "weight_expr")]
    pub weight_attribute: Option<String>,
    /// Painted weights ω as an expression of the rest position `x, y, z`, clamped to [0, 1],
    /// e.g. "clamp01(y / 2)".
    #[arg(long)]
    pub weight_expr: Option<String>,
}

impl EffectArgs {
    /// The painted-weight source the flags ask for, if any.
    pub fn weight_source(&self) -> Option<WeightSource> {
        if !self.weight_group.is_empty() {
            return Some(WeightSource::Group(WeightGroup {
                group: self.weight_group.clone(),
                descendants: !self.weight_group_only,
            }));
        }
        if let Some(a) = &self.weight_attribute {
            return Some(WeightSource::Attribute(WeightAttribute {
                attribute: a.clone(),
            }));
        }
        self.weight_expr
            .as_ref()
            .map(|e| WeightSource::Function(FunctionSpec::expr(e, &[])))
    }

    /// A preset stylization function, multiplied by ω when painted weights are given.
    pub fn weighted(&self, mut preset: FunctionSpec) -> FunctionSpec {
        if self.weight_source().is_some() && preset.expr.is_none() {
            preset.stages.push(Stage::Weight);
        }
        preset
    }
}

/// The input opened, merged, with its motion offsets, painted weights and camera.
pub struct Prepared {
    /// The sampled input.
    pub sampled: SampledScene,
    /// All objects merged into one cache.
    pub merged: MeshAnimation,
    /// Offsets of the merged cache.
    pub offsets: MotionOffsets,
    /// Motion-line seeds (sorted by triangle) and their offsets, when asked for.
    pub seeds: Option<(Vec<SurfacePoint>, MotionOffsets)>,
    /// Painted weights of the merged vertices.
    pub weights: Option<Vec<f32>>,
    /// The camera speeds are measured against (`--camera`).
    pub camera: Option<Camera>,
    /// Seconds spent.
    pub seconds: f64,
}

/// Opens and merges the input and computes its offsets and painted weights; with
/// `seeds = Some((K, seed))` also samples K motion-line seeds (sorted by triangle) and their
/// offsets, with the same solver.
///
/// # Errors
/// One line naming the input: unreadable, bad offset options, unknown joint/attribute/camera.
pub fn prepare(io: &EffectIo, a: &EffectArgs, seeds: Option<(usize, u64)>) -> Result<Prepared> {
    let start = Instant::now();
    let path = io.input.as_path();
    if a.step == 0 {
        bail!("--step must be ≥ 1 (1 = on ones, 2 = on twos)");
    }
    let sampled = input::open(path, &io.input_args)?;
    let merged = input::merged(path, &sampled)?;
    let options = a.offsets.options(&sampled);
    let camera = options
        .selected_camera(&sampled.cameras)
        .map_err(at_input(path))?
        .cloned();
    let solver = OffsetSolver::new(&sampled, &options).map_err(at_input(path))?;
    let offsets = MotionOffsets::concat(&solver.all())?;
    let seeds = match seeds {
        Some((count, seed)) => Some(seed_offsets(path, &sampled, &merged, &solver, count, seed)?),
        None => None,
    };
    drop(solver);
    let weights = match a.weight_source() {
        Some(source) => {
            let mut all = Vec::with_capacity(merged.vertex_count());
            for i in 0..sampled.objects.len() {
                all.extend(source.vertex_weights(&sampled, i).map_err(at_input(path))?);
            }
            Some(all)
        }
        None => None,
    };
    Ok(Prepared {
        sampled,
        merged,
        offsets,
        seeds,
        weights,
        camera,
        seconds: start.elapsed().as_secs_f64(),
    })
}

impl Prepared {
    /// The effect inputs of the merged vertices (weights and camera-relative speed applied).
    ///
    /// # Errors
    /// Shape mismatches (not expected: everything comes from one input).
    pub fn vertex_inputs(&self) -> Result<EffectInputs<'_>> {
        let inputs = EffectInputs::new(&self.merged, &self.offsets)?;
        self.finish(inputs, self.weights.clone())
    }

    /// The effect inputs of the motion-line seeds (weights interpolated at the seeds), and the
    /// number of seeds.
    ///
    /// # Errors
    /// No seeds were prepared, or a seed is off the mesh.
    pub fn seed_inputs(&mut self) -> Result<(EffectInputs<'static>, usize)> {
        let Some((pts, offsets)) = self.seeds.take() else {
            bail!("no motion-line seeds");
        };
        let weights = match &self.weights {
            Some(w) => Some(smear::surface_point_weights(
                w,
                &self.merged.mesh.triangles,
                &pts,
            )?),
            None => None,
        };
        let inputs = EffectInputs::at_surface_points(&self.merged, &pts, offsets)?;
        Ok((self.finish(inputs, weights)?, pts.len()))
    }

    fn finish<'a>(
        &self,
        mut inputs: EffectInputs<'a>,
        weights: Option<Vec<f32>>,
    ) -> Result<EffectInputs<'a>> {
        if let Some(w) = weights {
            inputs = inputs.with_weights(w)?;
        }
        Ok(inputs.relative_to_camera(self.camera.as_ref()))
    }
}

/// Maps a smear error to one line naming the input.
pub fn at_input(path: &Path) -> impl Fn(smear::SmearError) -> anyhow::Error + '_ {
    move |e| anyhow::anyhow!("{}: {e}", path.display())
}

/// Seeds on the merged mesh, sorted by triangle so they group by object, with their offsets
/// from each object's solver (Eq. 8 at the seeds' own positions).
fn seed_offsets(
    path: &Path,
    sampled: &SampledScene,
    merged: &MeshAnimation,
    solver: &OffsetSolver<'_>,
    count: usize,
    seed: u64,
) -> Result<(Vec<SurfacePoint>, MotionOffsets)> {
    let mut pts = smear::sample_surface(merged.frame(0), &merged.mesh.triangles, count, seed);
    pts.sort_by_key(|s| s.triangle);
    let mut parts = Vec::new();
    let (mut base, mut k) = (0u32, 0usize);
    for (i, o) in sampled.objects.iter().enumerate() {
        let end = base + o.animation.mesh.triangles.len() as u32;
        let local: Vec<SurfacePoint> = pts[k..]
            .iter()
            .take_while(|s| s.triangle < end)
            .map(|s| SurfacePoint {
                triangle: s.triangle - base,
                ..*s
            })
            .collect();
        k += local.len();
        parts.push(solver.surface_offsets(i, &local).map_err(at_input(path))?);
        base = end;
    }
    let frames = merged.frame_count();
    let offsets = if parts.is_empty() {
        MotionOffsets::zeros(frames, 0)
    } else {
        MotionOffsets::concat(&parts)?
    };
    Ok((pts, offsets))
}
