//! The data model of a USD layer: a root `Xform` holding animated `Mesh` prims.

use anim::glam::Vec3;
use anim::{Curves, Mesh, MeshAnimation, DEFAULT_FPS};

use crate::{IoError, Result};

/// Name of the root `Xform` prim (the layer's `defaultPrim`) unless the caller picks one.
pub const DEFAULT_ROOT_NAME: &str = "root";
/// Time code of the first frame: frame `k` is written at `DEFAULT_START_TIME_CODE + k`
/// (Blender and Houdini start their frame ranges at 1).
pub const DEFAULT_START_TIME_CODE: f64 = 1.0;
/// Scene units in metres: glTF positions are metres.
pub const DEFAULT_METERS_PER_UNIT: f64 = 1.0;

/// Where the frames of one mesh prim come from.
#[derive(Debug, Clone)]
pub enum UsdGeometry<'a> {
    /// A point cache: fixed topology (the mesh's polygons when it has them, else its
    /// triangles), one set of points per frame, optional per-frame RGBA vertex colours
    /// (frame-major, `frames × vertices`, linear). A frame whose colours all have alpha 0
    /// is absent (`visibility` "invisible").
    Animation {
        /// The cache.
        animation: &'a MeshAnimation,
        /// Per-frame vertex colours.
        colors: Option<&'a [[f32; 4]]>,
    },
    /// One mesh per frame, with its own topology and vertex colours ([`Mesh::colors`]):
    /// subdivided smears, tube motion lines. A frame with no mesh, no vertex or no triangle is
    /// absent (empty arrays, `visibility` "invisible").
    Frames {
        /// The mesh of every frame.
        meshes: Vec<&'a Mesh>,
        /// Optional velocities of every frame's vertices in units per frame (one per vertex
        /// of that frame's mesh), written as `velocities` per second.
        velocities: Option<Vec<&'a [Vec3]>>,
    },
    /// Linear curves per frame, written as a `BasisCurves` prim (width and colour per
    /// point): motion lines. A frame without a curve is absent (`visibility` "invisible").
    Curves(Vec<&'a Curves>),
}

impl UsdGeometry<'_> {
    /// Number of frames this geometry holds.
    pub fn frame_count(&self) -> usize {
        match self {
            UsdGeometry::Animation { animation, .. } => animation.frame_count(),
            UsdGeometry::Frames { meshes, .. } => meshes.len(),
            UsdGeometry::Curves(curves) => curves.len(),
        }
    }
}

/// One `def Mesh` (or `def BasisCurves`) prim.
#[derive(Debug, Clone)]
pub struct UsdMesh<'a> {
    /// Prim name; sanitized to `[A-Za-z_][A-Za-z0-9_]*` and made unique among its siblings
    /// when written.
    pub name: String,
    /// Points, topology and colours per frame.
    pub geometry: UsdGeometry<'a>,
}

impl<'a> UsdMesh<'a> {
    /// A point cache prim named after its mesh.
    pub fn animation(animation: &'a MeshAnimation, colors: Option<&'a [[f32; 4]]>) -> Self {
        UsdMesh {
            name: animation.mesh.name.clone(),
            geometry: UsdGeometry::Animation { animation, colors },
        }
    }

    /// A `BasisCurves` prim with one set of curves per frame.
    pub fn curves(name: impl Into<String>, curves: Vec<&'a Curves>) -> Self {
        UsdMesh {
            name: name.into(),
            geometry: UsdGeometry::Curves(curves),
        }
    }

    /// A prim with one mesh per frame (topology may change from frame to frame).
    pub fn frames(name: impl Into<String>, meshes: Vec<&'a Mesh>) -> Self {
        UsdMesh {
            name: name.into(),
            geometry: UsdGeometry::Frames {
                meshes,
                velocities: None,
            },
        }
    }

    /// [`UsdMesh::frames`] whose vertices move: `velocities[f]` holds one velocity (units per
    /// frame) per vertex of `meshes[f]`.
    pub fn moving_frames(
        name: impl Into<String>,
        meshes: Vec<&'a Mesh>,
        velocities: Vec<&'a [Vec3]>,
    ) -> Self {
        UsdMesh {
            name: name.into(),
            geometry: UsdGeometry::Frames {
                meshes,
                velocities: Some(velocities),
            },
        }
    }
}

/// A whole layer: stage metadata and the mesh prims under one root `Xform`.
#[derive(Debug, Clone)]
pub struct UsdStage<'a> {
    /// Name of the root `Xform` (the `defaultPrim`), sanitized when written.
    pub root: String,
    /// Frames per second: `timeCodesPerSecond` and `framesPerSecond`.
    pub fps: f32,
    /// Time code of frame 0 (default [`DEFAULT_START_TIME_CODE`]).
    pub start_time_code: f64,
    /// `metersPerUnit` (default [`DEFAULT_METERS_PER_UNIT`]).
    pub meters_per_unit: f64,
    /// Mesh prims, in order.
    pub meshes: Vec<UsdMesh<'a>>,
}

impl<'a> UsdStage<'a> {
    /// A stage with the default root name, time codes and units.
    pub fn new(fps: f32, meshes: Vec<UsdMesh<'a>>) -> Self {
        UsdStage {
            root: DEFAULT_ROOT_NAME.to_string(),
            fps,
            start_time_code: DEFAULT_START_TIME_CODE,
            meters_per_unit: DEFAULT_METERS_PER_UNIT,
            meshes,
        }
    }

    /// Several point caches with the same frames: one mesh prim per cache (named after its
    /// mesh, with its optional per-frame colours), the first cache's frame rate.
    ///
    /// # Errors
    /// When `parts` is empty.
    pub fn from_parts(parts: &'a [(&'a MeshAnimation, Option<&'a [[f32; 4]]>)]) -> Result<Self> {
        let Some((first, _)) = parts.first() else {
            return Err(IoError::unsupported("nothing to write"));
        };
        let meshes = parts
            .iter()
            .map(|(a, c)| UsdMesh::animation(a, *c))
            .collect();
        Ok(UsdStage::new(first.fps, meshes))
    }

    /// Number of frames: the longest geometry (at least 1).
    pub fn frame_count(&self) -> usize {
        self.meshes
            .iter()
            .map(|m| m.geometry.frame_count())
            .max()
            .unwrap_or(1)
            .max(1)
    }
}

impl Default for UsdStage<'_> {
    fn default() -> Self {
        UsdStage::new(DEFAULT_FPS, Vec::new())
    }
}
