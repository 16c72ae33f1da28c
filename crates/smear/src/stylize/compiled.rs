//! A style compiled for one object: its stylization functions ready to evaluate, in scene
//! units per frame whatever the style's units (docs/smear-units.md).

use super::error::StyleError;
use super::function::StyleFunction;
use super::style::ObjectEffects;
use super::units::StyleUnits;
use super::weights::WeightSource;
use crate::{ElongateOptions, LineOptions, MultiplesOptions};

/// Compiled functions of one object's effects (see [`ObjectEffects::compile`]).
#[derive(Debug, Clone)]
pub struct CompiledEffects {
    /// Where the painted weights come from (resolve with
    /// [`WeightSource::vertex_weights`]).
    pub weights: Option<WeightSource>,
    /// S_E and the elongation options.
    pub elongate: Option<(StyleFunction, ElongateOptions)>,
    /// S_M and the multiples options.
    pub multiples: Option<(StyleFunction, MultiplesOptions)>,
    /// S_L length, thickness, opacity and the line options.
    pub lines: Option<CompiledLines>,
}

/// Compiled motion-line functions.
#[derive(Debug, Clone)]
pub struct CompiledLines {
    /// τ = S_L.
    pub length: StyleFunction,
    /// Radius.
    pub thickness: StyleFunction,
    /// Opacity.
    pub opacity: StyleFunction,
    /// Options.
    pub options: LineOptions,
    /// Number of seeds to sample (the largest keyed count).
    pub count: usize,
    /// Seed of the sampling.
    pub seed: u64,
}

impl CompiledEffects {
    /// `Err` naming the first user expression of these effects that was NaN or infinite
    /// since the last check, with the frame and the vertex (motion line for the lines'
    /// functions). Called after the effects ran: the evaluations keep the geometry defined
    /// and remember where.
    ///
    /// # Errors
    /// [`StyleError::NotFinite`].
    pub fn check_finite(&self) -> Result<(), StyleError> {
        if let Some((f, _)) = &self.elongate {
            f.check_finite("vertex")?;
        }
        if let Some((f, _)) = &self.multiples {
            f.check_finite("vertex")?;
        }
        if let Some(l) = &self.lines {
            for f in [&l.length, &l.thickness, &l.opacity] {
                f.check_finite("motion line")?;
            }
        }
        Ok(())
    }
}

impl ObjectEffects<'_> {
    /// Compiles the functions of a style in scene units; `diagonal` is the object's
    /// bounding-box diagonal (default line thickness).
    pub fn compile(&self, diagonal: f32) -> Result<CompiledEffects, StyleError> {
        self.compile_in(diagonal, &StyleUnits::SCENE)
    }

    /// Compiles the functions of a style whose speeds and lengths are in `units`
    /// ([`Prepared::units`](crate::Prepared::units)): the compiled functions and options
    /// work in scene units per frame, as the effects do.
    pub fn compile_in(
        &self,
        diagonal: f32,
        units: &StyleUnits,
    ) -> Result<CompiledEffects, StyleError> {
        Ok(CompiledEffects {
            weights: self.weights.cloned(),
            elongate: match self.elongate {
                Some(e) => Some((
                    e.function.compile_in(units, 1.0)?,
                    ElongateOptions { step: e.step },
                )),
                None => None,
            },
            multiples: match self.multiples {
                Some(m) => Some((m.opacity_spec().compile_in(units, 1.0)?, m.options()?)),
                None => None,
            },
            lines: match self.lines {
                Some(l) => Some(CompiledLines {
                    length: l.length.compile_in(units, 1.0)?,
                    // The default is a fraction of the object's own diagonal in any units.
                    thickness: match &l.thickness {
                        Some(t) => t.compile_in(units, units.length)?,
                        None => l.thickness_spec(diagonal).compile()?,
                    },
                    opacity: l.opacity.compile_in(units, 1.0)?,
                    options: LineOptions {
                        min_speed: units.speed_to_scene(&l.min_speed),
                        ..l.options()
                    },
                    count: l.seed_count(),
                    seed: l.seed,
                }),
                None => None,
            },
        })
    }
}
