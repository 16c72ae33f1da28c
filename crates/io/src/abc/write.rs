//! The Alembic writer: one `PolyMesh` object per mesh prim of a [`UsdStage`].

use std::collections::HashMap;

use anim::glam::Vec3;
use anim::MeshAnimation;

use super::ogawa::{Ref, Writer};
use super::schema::{self, Kind, Pod, PropertyHeader};
use crate::usda::source::{check, extent, finite, Faces, Source};
use crate::usda::{UniqueNames, UsdStage};
use crate::Result;

/// Version of the AbcCoreOgawa layout written (readers accept 0 and later).
const FILE_VERSION: i32 = 0;
/// Alembic library version the layout matches (1.7.9; readers want ≥ 9999).
const LIBRARY_VERSION: i32 = 10709;
/// Index of the uniform per-frame time sampling (0 is Alembic's identity sampling).
const FRAME_SAMPLING: u32 = 1;

/// Writes one point cache as an Alembic archive (see the [module documentation](super)).
///
/// # Errors
/// As [`write()`].
pub fn write_animation(anim: &MeshAnimation, colors: Option<&[[f32; 4]]>) -> Result<Vec<u8>> {
    write_parts(&[(anim, colors)])
}

/// Writes several point caches with the same frames into one archive: one `PolyMesh` per
/// cache, the first cache's frame rate.
///
/// # Errors
/// When there is nothing to write, or as [`write()`].
pub fn write_parts(parts: &[(&MeshAnimation, Option<&[[f32; 4]]>)]) -> Result<Vec<u8>> {
    write(&UsdStage::from_parts(parts)?)
}

/// Writes a whole stage as an Alembic (Ogawa) archive: the same meshes, frames and times as
/// the `.usda`/`.usdc` of the stage. The same stage always gives the same bytes.
///
/// # Errors
/// The errors of [`crate::usda::write`]: bad frame rate, frame counts, colours, indices.
pub fn write(stage: &UsdStage) -> Result<Vec<u8>> {
    let sources = check(stage)?;
    let frames = stage.frame_count();
    let estimate: usize = sources
        .iter()
        .map(|s| (0..s.frames).map(|f| s.points(f).len() * 12).sum::<usize>())
        .sum();
    let mut archive = Archive {
        w: Writer::with_capacity(estimate * 11 / 10 + 4096),
        written: HashMap::new(),
        frames: frames as u32,
    };
    let mut names = UniqueNames::new();
    let mut children = Vec::new();
    let mut headers = Vec::new();
    for (mesh, source) in stage.meshes.iter().zip(&sources) {
        let name = names.claim(&mesh.name);
        children.push(archive.polymesh(source));
        schema::push_object_header(&mut headers, &name, schema::POLYMESH_OBJECT);
    }
    let top_properties = archive.compound(Vec::new(), Vec::new());
    let top = archive.object(top_properties, children, headers);

    let w = &mut archive.w;
    let version = w.data(&[&FILE_VERSION.to_le_bytes()]);
    let library = w.data(&[&LIBRARY_VERSION.to_le_bytes()]);
    let metadata = w.data(&[b"_ai_Application=toonkit;_ai_Description=toonkit scene cache"]);
    let samplings = w.data(&[&time_samplings(stage, frames)]);
    let indexed_metadata = w.data(&[]);
    let root = w.group(&[version, library, top, metadata, samplings, indexed_metadata]);
    Ok(archive.w.finish(root))
}

/// The archive's time samplings: 0, Alembic's identity (one sample per second from 0); 1,
/// one sample per frame from `start_time_code / fps` seconds, so frame `k` is at
/// `(start_time_code + k) / fps` seconds (frame `start_time_code + k` of a scene at `fps`).
fn time_samplings(stage: &UsdStage, frames: usize) -> Vec<u8> {
    let fps = stage.fps as f64;
    let mut out = Vec::new();
    for (max_samples, per_cycle, start) in [
        (0u32, 1.0f64, 0.0f64),
        (frames as u32, 1.0 / fps, stage.start_time_code / fps),
    ] {
        schema::push_u32(&mut out, max_samples);
        out.extend_from_slice(&per_cycle.to_le_bytes());
        schema::push_u32(&mut out, 1);
        out.extend_from_slice(&start.to_le_bytes());
    }
    out
}

/// An archive being written.
struct Archive {
    w: Writer,
    /// Data blocks already written, by content key: equal samples are stored once.
    written: HashMap<u128, Ref>,
    frames: u32,
}

/// The samples of one property, one byte string per frame.
struct Samples {
    bytes: Vec<Vec<u8>>,
}

impl Samples {
    fn per_frame(frames: u32, value: impl Fn(usize) -> Vec<u8>) -> Samples {
        Samples {
            bytes: (0..frames as usize).map(value).collect(),
        }
    }

    /// Whether every frame equals frame 0.
    fn constant(&self) -> bool {
        self.bytes.iter().all(|b| *b == self.bytes[0])
    }
}

impl Archive {
    /// One property's samples: stored once when constant, else one per frame (a data block
    /// of a 16-byte content key and the values; arrays add an empty dimensions block, their
    /// length following from the data size).
    fn property(
        &mut self,
        name: &str,
        kind: Kind,
        pod: Pod,
        extent: u32,
        metadata: &str,
        samples: &Samples,
    ) -> (PropertyHeader, Ref) {
        let constant = samples.constant();
        let stored = if constant {
            &samples.bytes[..1]
        } else {
            &samples.bytes[..]
        };
        let homogenous = stored.iter().all(|b| b.len() == stored[0].len());
        let mut children = Vec::with_capacity(stored.len() * 2);
        for bytes in stored {
            let key = twox_hash::XxHash3_128::oneshot(bytes);
            let w = &mut self.w;
            let data = *self
                .written
                .entry(key)
                .or_insert_with(|| w.data(&[&key.to_le_bytes(), bytes]));
            children.push(data);
            if kind == Kind::Array {
                children.push(self.w.data(&[]));
            }
        }
        let group = self.w.group(&children);
        let frames = self.frames;
        let header = PropertyHeader {
            name: name.to_string(),
            kind,
            pod: pod as u32,
            extent,
            samples: frames,
            first_changed: if constant { 0 } else { 1 },
            last_changed: if constant { 0 } else { frames - 1 },
            time_sampling: FRAME_SAMPLING,
            homogenous,
            metadata: metadata.to_string(),
        };
        (header, group)
    }

    /// A compound property: its children's groups, then their packed headers.
    fn compound(&mut self, mut groups: Vec<Ref>, headers: Vec<PropertyHeader>) -> Ref {
        let mut packed = Vec::new();
        for h in &headers {
            schema::push_property_header(&mut packed, h);
        }
        groups.push(self.w.data(&[&packed]));
        self.w.group(&groups)
    }

    /// An object: its properties, its children, then the children's headers and 32 bytes of
    /// hashes (of the headers written, so equal objects hash alike).
    fn object(&mut self, properties: Ref, children: Vec<Ref>, mut headers: Vec<u8>) -> Ref {
        let hash = twox_hash::XxHash3_128::oneshot(&headers).to_le_bytes();
        headers.extend_from_slice(&hash);
        headers.extend_from_slice(&hash);
        let mut group = vec![properties];
        group.extend(children);
        group.push(self.w.data(&[&headers]));
        self.w.group(&group)
    }

    /// One `PolyMesh` object (schema `AbcGeom_PolyMesh_v1`): `.geom` holds `P`,
    /// `.faceIndices`, `.faceCounts`, `.selfBnds` and, with colours, `.arbGeomParams` `Cd`
    /// (RGBA) and `alpha`; the object's `visible` property is keyed when frames are absent.
    fn polymesh(&mut self, source: &Source) -> Ref {
        let n = self.frames;
        let mut geom = Vec::new();
        let mut headers = Vec::new();
        let mut add = |(h, g): (PropertyHeader, Ref)| {
            headers.push(h);
            geom.push(g);
        };
        let points = Samples::per_frame(n, |f| points_bytes(source.points(f)));
        add(self.property("P", Kind::Array, Pod::Float32, 3, schema::POINTS, &points));
        drop(points);
        let indices = Samples::per_frame(n, |f| ints_bytes(&alembic_indices(source.faces(f))));
        add(self.property(".faceIndices", Kind::Array, Pod::Int32, 1, "", &indices));
        let counts = Samples::per_frame(n, |f| ints_bytes(&source.faces(f).counts()));
        add(self.property(".faceCounts", Kind::Array, Pod::Int32, 1, "", &counts));
        let bounds = Samples::per_frame(n, |f| {
            let (lo, hi) = extent(source.points(f));
            [lo, hi]
                .iter()
                .flat_map(|v| v.to_array())
                .flat_map(|x| (x as f64).to_le_bytes())
                .collect()
        });
        add(self.property(
            ".selfBnds",
            Kind::Scalar,
            Pod::Float64,
            6,
            schema::BOX,
            &bounds,
        ));

        if source.colors(0).is_some() {
            let color = |f: usize, channels: std::ops::Range<usize>| -> Vec<u8> {
                let Some(c) = source.colors(f) else {
                    return Vec::new();
                };
                (0..c.len())
                    .flat_map(|i| c.get(i)[channels.clone()].to_vec())
                    .flat_map(|x| finite(x).to_le_bytes())
                    .collect()
            };
            let rgba = Samples::per_frame(n, |f| color(f, 0..4));
            let alpha = Samples::per_frame(n, |f| color(f, 3..4));
            let params = vec![
                self.property(
                    "Cd",
                    Kind::Array,
                    Pod::Float32,
                    4,
                    schema::VERTEX_RGBA,
                    &rgba,
                ),
                self.property(
                    "alpha",
                    Kind::Array,
                    Pod::Float32,
                    1,
                    schema::VERTEX_FLOAT,
                    &alpha,
                ),
            ];
            let (h, g): (Vec<_>, Vec<_>) = params.into_iter().unzip();
            let group = self.compound(g, h);
            add((compound_header(".arbGeomParams", ""), group));
        }
        let geom = self.compound(geom, headers);

        let mut object_props = vec![geom];
        let mut object_headers = vec![compound_header(".geom", schema::POLYMESH_SCHEMA)];
        if source.any_absent() {
            let visible = Samples::per_frame(n, |f| vec![source.present(f) as u8]);
            let (h, g) = self.property("visible", Kind::Scalar, Pod::Int8, 1, "", &visible);
            object_props.push(g);
            object_headers.push(h);
        }
        let properties = self.compound(object_props, object_headers);
        self.object(properties, Vec::new(), Vec::new())
    }
}

/// The header of a compound property.
fn compound_header(name: &str, metadata: &str) -> PropertyHeader {
    PropertyHeader {
        name: name.to_string(),
        kind: Kind::Compound,
        pod: 0,
        extent: 0,
        samples: 0,
        first_changed: 0,
        last_changed: 0,
        time_sampling: 0,
        homogenous: true,
        metadata: metadata.to_string(),
    }
}

/// Face vertex indices in Alembic's winding: each face's vertices in reverse (Alembic faces
/// are clockwise seen from the front, glTF's and USD's counter-clockwise).
fn alembic_indices(faces: Faces) -> Vec<i32> {
    let counts = faces.counts();
    let mut indices = faces.indices();
    let mut at = 0;
    for c in counts {
        let c = c as usize;
        indices[at..at + c].reverse();
        at += c;
    }
    indices
}

/// Points as little-endian `f32` triples; non-finite coordinates become 0.
fn points_bytes(points: &[Vec3]) -> Vec<u8> {
    let mut out = Vec::with_capacity(points.len() * 12);
    for p in points {
        for x in p.to_array() {
            out.extend_from_slice(&finite(x).to_le_bytes());
        }
    }
    out
}

fn ints_bytes(values: &[i32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}
