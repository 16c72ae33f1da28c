//! USD binary export (`.usdc` crate files, and `.usdz` packages holding one), written with the
//! `openusd` crate from the same [`UsdStage`] as the text writer [`crate::usda`].
//!
//! The layer holds exactly what the `.usda` layer of the same stage holds (see the
//! [`usda` module documentation](crate::usda) for the layout): the same stage metadata
//! (`defaultPrim`, `startTimeCode`/`endTimeCode`, `framesPerSecond`/`timeCodesPerSecond`,
//! `metersPerUnit`, `upAxis = "Y"`), one root `Xform`, one `Mesh` prim per [`UsdMesh`](crate::usda::UsdMesh) with the
//! same names, the same properties (`faceVertexCounts`, `faceVertexIndices`, `points`,
//! `extent`, `primvars:st`, `primvars:displayColor`, `primvars:displayOpacity`,
//! `visibility`), and the same time samples: frame `k` at time code `start_time_code + k`, an
//! attribute that never changes written once as its default value.
//!
//! Floats are stored as raw `f32` and integer arrays compressed, so a point cache is about
//! 12 bytes per point and frame instead of ~40 as text (RobotExpressive, 21 frames: see
//! `crates/io/tests/usdc.rs`).
//!
//! # Example
//! ```
//! use anim::glam::Vec3;
//! use anim::{Mesh, MeshAnimation};
//!
//! let tri = Mesh::new("tri", vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
//! let mut frames = tri.positions.clone();
//! frames.extend(tri.positions.iter().map(|p| *p + Vec3::Z));
//! let anim = MeshAnimation::new(tri, 24.0, frames).unwrap();
//! let bytes = tkio::usdc::write_animation(&anim, None).unwrap();
//! assert!(bytes.starts_with(b"PXR-USDC"));
//! ```

mod children;

use std::io::Cursor;

use anim::glam::Vec3;
use anim::MeshAnimation;
use openusd::gf;
use openusd::sdf::{self, ChildrenKey, FieldKey, SpecType, Specifier, Value, Variability};

use crate::usda::source::{check, finite, ColorsOf, Source};
use crate::usda::{sanitize_name, UniqueNames, UsdStage};
use crate::{IoError, Result};

/// Writes one point cache as a `.usdc` layer (see [`crate::usda::write_animation`]).
///
/// # Errors
/// As [`write()`].
pub fn write_animation(anim: &MeshAnimation, colors: Option<&[[f32; 4]]>) -> Result<Vec<u8>> {
    write_parts(&[(anim, colors)])
}

/// Writes several point caches with the same frames into one `.usdc` layer (see
/// [`crate::usda::write_parts`]).
///
/// # Errors
/// When there is nothing to write, or as [`write()`].
pub fn write_parts(parts: &[(&MeshAnimation, Option<&[[f32; 4]]>)]) -> Result<Vec<u8>> {
    write(&UsdStage::from_parts(parts)?)
}

/// Writes a whole stage as a `.usdc` crate file. The same stage always gives the same bytes.
///
/// # Errors
/// The errors of [`crate::usda::write`] (bad frame rate, frame counts, colours, indices), and
/// [`IoError::Encode`] when the crate writer fails.
pub fn write(stage: &UsdStage) -> Result<Vec<u8>> {
    let data = layer(stage)?;
    let mut out = Cursor::new(Vec::new());
    openusd::usdc::CrateWriter::write(&data, &mut out).map_err(|e| IoError::encode("USD", e))?;
    children::retype_children(out.into_inner())
}

/// Whether curves with these counts per frame can be written as `.usdc` (an `int[]` of 4 to
/// 15 elements cannot, see [`write()`]'s errors): motion lines are written as
/// `BasisCurves` then, else as the tube meshes swept along them.
pub fn holds_curves(curves: &[&anim::Curves]) -> bool {
    curves
        .iter()
        .all(|c| !MISREAD_INT_ARRAYS.contains(&c.counts.len()))
}

/// Writes a stage as a `.usdz` package: one `.usdc` layer (named after the root prim) stored
/// uncompressed and 64-byte aligned, as the USDZ specification asks.
///
/// # Errors
/// As [`write()`].
pub fn write_usdz(stage: &UsdStage) -> Result<Vec<u8>> {
    let layer = write(stage)?;
    let mut zip = openusd::usdz::ArchiveWriter::new(Cursor::new(Vec::new()));
    let name = format!("{}.usdc", sanitize_name(&stage.root));
    zip.add_layer(&name, &layer)
        .map_err(|e| IoError::encode("USDZ", e))?;
    let out = zip.finish().map_err(|e| IoError::encode("USDZ", e))?;
    Ok(out.into_inner())
}

/// Lengths of `int[]` arrays that `openusd` 0.6 compresses but Pixar's USD reads as
/// uncompressed (Pixar compresses from 16 elements, `openusd` from 4): refused rather than
/// written wrong.
const MISREAD_INT_ARRAYS: std::ops::Range<usize> = 4..16;

/// The whole layer as `openusd` scene description.
fn layer(stage: &UsdStage) -> Result<sdf::Data> {
    let sources = check(stage)?;
    let frames = stage.frame_count();
    for (mesh, source) in stage.meshes.iter().zip(&sources) {
        let small = (0..frames).find(|&f| {
            let faces = source.faces(f);
            let (c, i) = (faces.counts().len(), faces.indices().len());
            MISREAD_INT_ARRAYS.contains(&c) || MISREAD_INT_ARRAYS.contains(&i)
        });
        let small = small.or_else(|| {
            (0..frames).find(|&f| MISREAD_INT_ARRAYS.contains(&source.curve_counts(f).len()))
        });
        if let Some(f) = small {
            return Err(IoError::unsupported(format!(
                "USD mesh '{}' frame {}: meshes of 2 to 15 faces cannot be written as .usdc yet \
                 (the openusd crate compresses their index arrays in a way Pixar's USD misreads); \
                 write .usda or .abc",
                mesh.name,
                f + 1
            )));
        }
    }
    let root = sanitize_name(&stage.root);
    let t0 = stage.start_time_code;
    let mut data = sdf::Data::new();
    let pseudo = data.create_spec(sdf::Path::abs_root(), SpecType::PseudoRoot);
    pseudo.add(FieldKey::DefaultPrim, Value::Token(root.as_str().into()));
    pseudo.add(FieldKey::StartTimeCode, Value::Double(t0));
    pseudo.add(
        FieldKey::EndTimeCode,
        Value::Double(t0 + (frames - 1) as f64),
    );
    pseudo.add(FieldKey::FramesPerSecond, Value::Double(stage.fps as f64));
    pseudo.add(
        FieldKey::TimeCodesPerSecond,
        Value::Double(stage.fps as f64),
    );
    pseudo.add("metersPerUnit", Value::Double(stage.meters_per_unit));
    pseudo.add("upAxis", Value::Token("Y".into()));
    pseudo.add(
        ChildrenKey::PrimChildren,
        Value::TokenVec(vec![root.as_str().into()]),
    );

    let mut names = UniqueNames::new();
    let children: Vec<String> = stage.meshes.iter().map(|m| names.claim(&m.name)).collect();
    let root_path = prim_path(&format!("/{root}"))?;
    let xform = data.create_spec(root_path.clone(), SpecType::Prim);
    xform.add(FieldKey::Specifier, Value::Specifier(Specifier::Def));
    xform.add(FieldKey::TypeName, Value::Token("Xform".into()));
    xform.add(
        ChildrenKey::PrimChildren,
        Value::TokenVec(children.iter().map(|c| c.as_str().into()).collect()),
    );
    for (name, source) in children.iter().zip(&sources) {
        let path = prim_path(&format!("/{root}/{name}"))?;
        let mut prim = Prim {
            data: &mut data,
            path: &path,
            properties: Vec::new(),
            t0,
        };
        let kind = if source.is_curves() {
            prim.curves(source);
            "BasisCurves"
        } else {
            prim.mesh(source);
            "Mesh"
        };
        let properties = std::mem::take(&mut prim.properties);
        let spec = data.create_spec(path.clone(), SpecType::Prim);
        spec.add(FieldKey::Specifier, Value::Specifier(Specifier::Def));
        spec.add(FieldKey::TypeName, Value::Token(kind.into()));
        spec.add(ChildrenKey::PropertyChildren, Value::TokenVec(properties));
    }
    Ok(data)
}

fn prim_path(text: &str) -> Result<sdf::Path> {
    sdf::path(text).map_err(|e| IoError::encode("USD", e))
}

/// One mesh prim being filled with attributes.
struct Prim<'d> {
    data: &'d mut sdf::Data,
    path: &'d sdf::Path,
    properties: Vec<openusd::tf::Token>,
    t0: f64,
}

/// How an attribute's value is written.
enum Samples {
    /// The same value on every frame: the attribute's default.
    Constant(Value),
    /// One value per frame, at time codes `t0 + f`.
    PerFrame(Vec<Value>),
}

impl Samples {
    /// One value when `is_static` (or one frame), else one per frame.
    fn of(frames: usize, is_static: bool, value: &dyn Fn(usize) -> Value) -> Samples {
        if is_static || frames == 1 {
            Samples::Constant(value(0))
        } else {
            Samples::PerFrame((0..frames).map(value).collect())
        }
    }
}

impl Prim<'_> {
    /// The properties of a mesh prim, in the order of the `.usda` writer.
    fn mesh(&mut self, source: &Source) {
        let frames = source.frames;
        let samples =
            |is_static: bool, value: &dyn Fn(usize) -> Value| Samples::of(frames, is_static, value);
        self.uniform_token("orientation", "rightHanded");
        self.uniform_token("subdivisionScheme", "none");
        let topology_static = source.topology_static();
        let counts = samples(topology_static, &|f| {
            Value::IntVec(source.faces(f).counts())
        });
        self.attribute("faceVertexCounts", "int[]", None, counts);
        let indices = samples(topology_static, &|f| {
            Value::IntVec(source.faces(f).indices())
        });
        self.attribute("faceVertexIndices", "int[]", None, indices);

        let points_static = source.points_static();
        let points = samples(points_static, &|f| vec3s(source.points(f)));
        self.attribute("points", "point3f[]", None, points);
        let extents = samples(points_static, &|f| {
            let (lo, hi) = source.extent(f);
            vec3s(&[lo, hi])
        });
        self.attribute("extent", "float3[]", None, extents);
        if source.has_velocities() {
            let v = Samples::PerFrame((0..frames).map(|f| vec3s(&source.velocities(f))).collect());
            self.attribute("velocities", "vector3f[]", None, v);
        }

        if let Some(uvs) = source.uvs() {
            let st = uvs
                .iter()
                .map(|uv| gf::Vec2f::from([finite(uv[0]), finite(1.0 - uv[1])]))
                .collect();
            let st = Samples::Constant(Value::Vec2fVec(st));
            self.attribute("primvars:st", "texCoord2f[]", Some("vertex"), st);
        }

        self.display(source);
    }

    /// The properties of a `BasisCurves` prim, in the order of the `.usda` writer.
    fn curves(&mut self, source: &Source) {
        let frames = source.frames;
        let samples =
            |is_static: bool, value: &dyn Fn(usize) -> Value| Samples::of(frames, is_static, value);
        self.uniform_token("type", "linear");
        self.uniform_token("wrap", "nonperiodic");
        let counts = samples(source.topology_static(), &|f| {
            Value::IntVec(source.curve_counts(f).iter().map(|&k| k as i32).collect())
        });
        self.attribute("curveVertexCounts", "int[]", None, counts);
        let points_static = source.points_static();
        let points = samples(points_static, &|f| vec3s(source.points(f)));
        self.attribute("points", "point3f[]", None, points);
        let extents = samples(points_static && source.widths_static(), &|f| {
            let (lo, hi) = source.extent(f);
            vec3s(&[lo, hi])
        });
        self.attribute("extent", "float3[]", None, extents);
        let widths = samples(source.widths_static(), &|f| {
            Value::FloatVec(source.widths(f).iter().map(|&w| finite(w)).collect())
        });
        self.attribute("widths", "float[]", Some("vertex"), widths);
        self.display(source);
    }

    /// Display colour and opacity (vertex primvars) and visibility, for meshes and curves.
    fn display(&mut self, source: &Source) {
        let frames = source.frames;
        let samples =
            |is_static: bool, value: &dyn Fn(usize) -> Value| Samples::of(frames, is_static, value);
        if source.colors(0).is_some() {
            let colors = |f: usize| source.colors(f).unwrap_or(ColorsOf::Given(&[]));
            let colors_static = source.colors_static();
            let rgb = samples(colors_static, &|f| {
                let c = colors(f);
                let rgb = (0..c.len())
                    .map(|i| {
                        let [r, g, b, _] = c.get(i);
                        gf::Vec3f::from([finite(r), finite(g), finite(b)])
                    })
                    .collect();
                Value::Vec3fVec(rgb)
            });
            self.attribute("primvars:displayColor", "color3f[]", Some("vertex"), rgb);
            let alpha = samples(colors_static, &|f| {
                let c = colors(f);
                Value::FloatVec((0..c.len()).map(|i| finite(c.get(i)[3])).collect())
            });
            let decl = "primvars:displayOpacity";
            self.attribute(decl, "float[]", Some("vertex"), alpha);
        }

        if source.any_absent() {
            let vis = samples(source.presence_static(), &|f| {
                let v = if source.present(f) {
                    "inherited"
                } else {
                    "invisible"
                };
                Value::Token(v.into())
            });
            self.attribute("visibility", "token", None, vis);
        }
    }

    /// A `uniform token` attribute.
    fn uniform_token(&mut self, name: &str, value: &str) {
        if let Some(spec) = self.spec(name, "token") {
            spec.add(
                FieldKey::Variability,
                Value::Variability(Variability::Uniform),
            );
            spec.add(FieldKey::Default, Value::Token(value.into()));
        }
    }

    /// An attribute of type `ty` with an optional `interpolation` and its samples.
    fn attribute(&mut self, name: &str, ty: &str, interpolation: Option<&str>, samples: Samples) {
        let t0 = self.t0;
        let Some(spec) = self.spec(name, ty) else {
            return;
        };
        if let Some(i) = interpolation {
            spec.add("interpolation", Value::Token(i.into()));
        }
        match samples {
            Samples::Constant(v) => spec.add(FieldKey::Default, v),
            Samples::PerFrame(values) => {
                let map = values
                    .into_iter()
                    .enumerate()
                    .map(|(f, v)| (t0 + f as f64, v))
                    .collect();
                spec.add(FieldKey::TimeSamples, Value::TimeSamples(map));
            }
        }
    }

    /// Creates the attribute spec `name` (typed `ty`, not custom) and lists it on the prim.
    /// Prim names are sanitized identifiers and attribute names are constants, so the path
    /// is always valid.
    fn spec(&mut self, name: &str, ty: &str) -> Option<&mut sdf::SpecData> {
        let path = self.path.append_property(name).ok()?;
        self.properties.push(name.into());
        let spec = self.data.create_spec(path, SpecType::Attribute);
        spec.add(FieldKey::TypeName, Value::Token(ty.into()));
        spec.add(FieldKey::Custom, Value::Bool(false));
        Some(spec)
    }
}

/// Points as written: non-finite coordinates become 0 (as in `.usda`).
fn vec3s(points: &[Vec3]) -> Value {
    Value::Vec3fVec(
        points
            .iter()
            .map(|p| gf::Vec3f::from([finite(p.x), finite(p.y), finite(p.z)]))
            .collect(),
    )
}
