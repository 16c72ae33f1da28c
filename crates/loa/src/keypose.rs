//! Key poses: keystrokes fitted with chains (LoA Eq. 1), angles unwrapped across keys.

use std::f64::consts::PI;

use crate::fit::{fit_chain, FitResidual};
use crate::keystroke::Keystrokes;
use crate::{Chain, LoaError};

/// A keystroke turned into a chain, ready for interpolation.
#[derive(Debug, Clone, PartialEq)]
pub struct KeyPose {
    /// Frame of the keystroke.
    pub frame: i64,
    /// The fitted chain. Its angles are unwrapped against the previous key (each differs from
    /// the previous key's by at most π), so interpolation turns the short way round.
    pub chain: Chain,
    /// Angular stiffness `k` (1/s²) of the interval starting here.
    pub stiffness: f64,
    /// Damping ratio `ζ` of the interval starting here.
    pub damping: f64,
    /// Residual of the chain fit (LoA Eq. 1).
    pub residual: FitResidual,
}

/// Fits every keystroke with `elements` rigid elements (LoA Eq. 1) and unwraps the angles so that
/// consecutive keys differ by at most π per angle.
pub fn fit_keystrokes(keys: &Keystrokes, elements: usize) -> Result<Vec<KeyPose>, LoaError> {
    let mut out: Vec<KeyPose> = Vec::with_capacity(keys.keys().len());
    for k in keys.keys() {
        let fit = fit_chain(&k.stroke, elements)?;
        let mut chain = fit.chain;
        if let Some(prev) = out.last() {
            for (a, p) in chain.angles_mut().iter_mut().zip(prev.chain.angles()) {
                *a = unwrap_near(*a, *p);
            }
        }
        out.push(KeyPose {
            frame: k.frame,
            chain,
            stiffness: k.stiffness,
            damping: k.damping,
            residual: fit.residual,
        });
    }
    Ok(out)
}

/// The angle equal to `a` modulo 2π that is closest to `reference`.
pub(crate) fn unwrap_near(a: f64, reference: f64) -> f64 {
    a - 2.0 * PI * ((a - reference) / (2.0 * PI)).round()
}
