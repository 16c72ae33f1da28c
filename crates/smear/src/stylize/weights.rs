//! Where a style's painted weights ω come from (paper Fig. 15b).

use anim::SampledScene;
use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::error::StyleError;
use super::function::FunctionSpec;
use super::units::StyleUnits;
use crate::effects::{attribute_weights, group_weights, StyleInput, Stylize};
use crate::SmearError;

fn yes() -> bool {
    true
}

/// A weight group: the skin weights of some joints.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WeightGroup {
    /// Joint names (case-sensitive).
    pub group: Vec<String>,
    /// Include every joint below the named ones (default true).
    #[serde(default = "yes")]
    pub descendants: bool,
}

/// A scalar vertex attribute painted in the animation package.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WeightAttribute {
    /// Attribute name, e.g. `_SMEAR_WEIGHT` (the leading `_` may be omitted), or a vertex
    /// colour channel `COLOR_0.r` / `.g` / `.b` / `.a`.
    pub attribute: String,
}

/// Painted weights ω ∈ [0, 1] per vertex, one of:
///
/// * `weights = { group = ["Head"], descendants = true }` — a weight group
///   ([`group_weights`](crate::group_weights));
/// * `weights = { attribute = "_SMEAR_WEIGHT" }` — a painted vertex attribute
///   ([`attribute_weights`](crate::attribute_weights));
/// * `weights = { expr = "...", params = { ... } }` (or `stages`) — a function of the rest
///   position `x, y, z` (other inputs 0), clamped to [0, 1].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum WeightSource {
    /// A weight group.
    Group(WeightGroup),
    /// A vertex attribute.
    Attribute(WeightAttribute),
    /// A function of the rest position.
    Function(FunctionSpec),
}

impl From<FunctionSpec> for WeightSource {
    fn from(f: FunctionSpec) -> Self {
        WeightSource::Function(f)
    }
}

impl WeightSource {
    /// Checks what can be checked without a scene (functions compile).
    pub fn validate(&self) -> Result<(), StyleError> {
        match self {
            WeightSource::Function(f) => f.compile().map(|_| ()),
            WeightSource::Group(g) if g.group.is_empty() => Err(StyleError::Parameter {
                name: "weights.group".into(),
                problem: "name at least one joint".into(),
            }),
            WeightSource::Attribute(a) if a.attribute.trim_start_matches('_').is_empty() => {
                Err(StyleError::Parameter {
                    name: "weights.attribute".into(),
                    problem: "give the attribute's name, e.g. \"_SMEAR_WEIGHT\"".into(),
                })
            }
            _ => Ok(()),
        }
    }

    /// Every weight source `scene` offers, for a weight-group picker (paper Fig. 15b): one
    /// group per joint of the skeleton (with its descendants) when an object is skinned or
    /// parented to a joint, each scalar vertex attribute of any object (by its name as stored,
    /// e.g. `_SMEAR_WEIGHT`), and the four `COLOR_0` channels when an object has vertex
    /// colours. Deterministic order: joints in skeleton order, then attributes by name, then
    /// colour channels.
    pub fn available(scene: &SampledScene) -> Vec<WeightSource> {
        let bound = scene
            .objects
            .iter()
            .any(|o| o.skin.is_some() || o.parent_joint.is_some());
        let mut out: Vec<WeightSource> = Vec::new();
        if bound {
            out.extend(scene.skeleton.joints.iter().map(|j| {
                WeightSource::Group(WeightGroup {
                    group: vec![j.name.clone()],
                    descendants: true,
                })
            }));
        }
        let names: std::collections::BTreeSet<&String> = scene
            .objects
            .iter()
            .flat_map(|o| o.animation.mesh.attributes.keys())
            .collect();
        let attribute = |name: String| WeightSource::Attribute(WeightAttribute { attribute: name });
        out.extend(names.into_iter().map(|n| attribute(n.clone())));
        if scene
            .objects
            .iter()
            .any(|o| o.animation.mesh.colors.is_some())
        {
            out.extend(["r", "g", "b", "a"].map(|c| attribute(format!("COLOR_0.{c}"))));
        }
        out
    }

    /// The weights of every vertex of object `object` of `scene`, a function reading the
    /// rest position in scene units.
    ///
    /// # Errors
    /// An unknown joint or attribute (naming the available ones), an object index out of
    /// range, or a function that does not compile.
    pub fn vertex_weights(
        &self,
        scene: &SampledScene,
        object: usize,
    ) -> Result<Vec<f32>, SmearError> {
        self.vertex_weights_in(scene, object, &StyleUnits::SCENE)
    }

    /// [`WeightSource::vertex_weights`] with a function reading the rest position `x, y, z`
    /// in a style's length units (`units`, see [`StyleUnits`]).
    ///
    /// # Errors
    /// As [`WeightSource::vertex_weights`].
    pub fn vertex_weights_in(
        &self,
        scene: &SampledScene,
        object: usize,
        units: &StyleUnits,
    ) -> Result<Vec<f32>, SmearError> {
        let obj = scene.objects.get(object).ok_or(SmearError::UnknownObject {
            index: object,
            count: scene.objects.len(),
        })?;
        match self {
            WeightSource::Group(g) => group_weights(scene, object, &g.group, g.descendants),
            WeightSource::Attribute(a) => attribute_weights(&obj.animation.mesh, &a.attribute),
            WeightSource::Function(f) => {
                let f = f
                    .compile_in(units, 1.0)
                    .map_err(|e| SmearError::InvalidParameter {
                        name: "weights",
                        reason: e.to_string(),
                    })?;
                let weights = function_weights(&f, obj.animation.frame(0));
                f.check_finite("vertex")?;
                Ok(weights)
            }
        }
    }
}

/// A one-line label for pickers and messages: `bone ShoulderR and below`,
/// `attribute _SMEAR_WEIGHT`, `vertex colour COLOR_0.r`, `function of the rest position`.
impl std::fmt::Display for WeightSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            WeightSource::Group(g) => write!(
                f,
                "{} {}{}",
                if g.group.len() == 1 { "bone" } else { "bones" },
                g.group.join(", "),
                if g.descendants { " and below" } else { "" }
            ),
            WeightSource::Attribute(a) if a.attribute.starts_with("COLOR_0.") => {
                write!(f, "vertex colour {}", a.attribute)
            }
            WeightSource::Attribute(a) => write!(f, "attribute {}", a.attribute),
            WeightSource::Function(_) => write!(f, "function of the rest position"),
        }
    }
}

/// ω = f(rest position), clamped to [0, 1]; non-finite values read 0 (and a user expression
/// remembers where, for the caller's check).
fn function_weights(f: &dyn Stylize, rest: &[Vec3]) -> Vec<f32> {
    rest.iter()
        .enumerate()
        .map(|(i, &p)| {
            let w = f.eval(&StyleInput {
                rest: p,
                weight: 1.0,
                vertex: i as u32,
                ..Default::default()
            });
            if w.is_finite() {
                w.clamp(0.0, 1.0)
            } else {
                0.0
            }
        })
        .collect()
}
