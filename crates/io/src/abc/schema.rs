//! The AbcCoreOgawa encoding of Alembic objects and properties, shared by the writer and the
//! reader: plain-old-data types, property header packing, metadata strings.

/// Plain-old-data type codes of Alembic (`Alembic::Util::PlainOldDataType`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub(crate) enum Pod {
    /// `int8_t` (object visibility).
    Int8 = 2,
    /// `int32_t` (face counts and indices).
    Int32 = 6,
    /// `float` (points, colours, alpha).
    Float32 = 10,
    /// `double` (bounds).
    Float64 = 11,
}

impl Pod {
    /// Bytes of one value.
    pub(crate) fn size(self) -> usize {
        match self {
            Pod::Int8 => 1,
            Pod::Int32 | Pod::Float32 => 4,
            Pod::Float64 => 8,
        }
    }

    /// The type of a header's code, if it is one toonkit reads.
    pub(crate) fn from_code(code: u32) -> Option<Pod> {
        Some(match code {
            2 => Pod::Int8,
            6 => Pod::Int32,
            10 => Pod::Float32,
            11 => Pod::Float64,
            _ => return None,
        })
    }
}

/// What a property is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    /// A group of properties.
    Compound,
    /// One value of `extent` pods per sample.
    Scalar,
    /// An array of values per sample.
    Array,
}

/// Bits of a property header's `info` word (AbcCoreOgawa).
pub(crate) mod info {
    /// Property type: 0 compound, 1 scalar, 2 array (3: scalar-like array).
    pub(crate) const KIND: u32 = 0x3;
    /// Byte width of the sizes that follow: 0 → 1 byte, 1 → 2, 2 → 4.
    pub(crate) const SIZE_HINT: u32 = 0xc;
    /// Plain-old-data type, bits 4–7.
    pub(crate) const POD: u32 = 0xf0;
    /// A time sampling index follows.
    pub(crate) const HAS_TIME_SAMPLING: u32 = 0x100;
    /// First and last changed sample indices follow.
    pub(crate) const FIRST_LAST: u32 = 0x200;
    /// Every sample has the same size.
    pub(crate) const HOMOGENOUS: u32 = 0x400;
    /// Every sample equals the first (one sample stored).
    pub(crate) const CONSTANT: u32 = 0x800;
    /// Extent (values per element), bits 12–19.
    pub(crate) const EXTENT: u32 = 0xff000;
    /// Index into the archive's metadata table, bits 20–27 (`0xff`: written inline).
    pub(crate) const METADATA: u32 = 0xff0_0000;
}

/// Metadata index of the empty metadata string.
pub(crate) const NO_METADATA: u32 = 0;
/// Metadata index meaning "the string follows inline".
pub(crate) const INLINE_METADATA: u32 = 0xff;

/// Object metadata of a polygon mesh.
pub(crate) const POLYMESH_OBJECT: &str =
    "schema=AbcGeom_PolyMesh_v1;schemaBaseType=AbcGeom_GeomBase_v1;schemaObjTitle=AbcGeom_PolyMesh_v1:.geom";
/// Metadata of a polygon mesh's `.geom` compound.
pub(crate) const POLYMESH_SCHEMA: &str =
    "schema=AbcGeom_PolyMesh_v1;schemaBaseType=AbcGeom_GeomBase_v1";
/// Metadata of point positions.
pub(crate) const POINTS: &str = "interpretation=point";
/// Metadata of a bounding box.
pub(crate) const BOX: &str = "interpretation=box";
/// Metadata of a per-vertex RGBA geometry parameter.
pub(crate) const VERTEX_RGBA: &str =
    "geoScope=vtx;interpretation=rgba;isGeomParam=true;podExtent=4;podName=float32_t";
/// Metadata of a per-vertex float geometry parameter.
pub(crate) const VERTEX_FLOAT: &str = "geoScope=vtx;isGeomParam=true;podExtent=1;podName=float32_t";

/// A decoded property header.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PropertyHeader {
    /// Property name.
    pub name: String,
    /// Compound, scalar or array.
    pub kind: Kind,
    /// Data type code (scalar and array).
    pub pod: u32,
    /// Values per element.
    pub extent: u32,
    /// Number of samples (frames).
    pub samples: u32,
    /// First sample that differs from sample 0.
    pub first_changed: u32,
    /// Last sample that differs from its predecessor.
    pub last_changed: u32,
    /// Index of the archive's time sampling.
    pub time_sampling: u32,
    /// Every sample has the same number of elements.
    pub homogenous: bool,
    /// Metadata, `key=value;…` (inline metadata only; indexed metadata is not read).
    pub metadata: String,
}

impl PropertyHeader {
    /// The stored sample holding frame `f` (repeated samples are stored once).
    pub(crate) fn stored_index(&self, f: u32) -> u32 {
        let constant = self.first_changed == 0 && self.last_changed == 0;
        if constant || f < self.first_changed {
            0
        } else if f >= self.last_changed {
            // Saturating: a malformed header may have its last change before its first.
            self.last_changed
                .saturating_sub(self.first_changed)
                .saturating_add(1)
        } else {
            f - self.first_changed + 1
        }
    }
}

/// Appends the packed header of one property (4-byte sizes throughout).
pub(crate) fn push_property_header(out: &mut Vec<u8>, h: &PropertyHeader) {
    let metadata_index = if h.metadata.is_empty() {
        NO_METADATA
    } else {
        INLINE_METADATA
    };
    let mut word = (2 << 2) | (metadata_index << 20);
    let mut first_last = false;
    if h.kind != Kind::Compound {
        word |= if h.kind == Kind::Scalar { 1 } else { 2 };
        word |= (h.pod << 4) & info::POD;
        word |= (h.extent << 12) & info::EXTENT;
        if h.homogenous {
            word |= info::HOMOGENOUS;
        }
        if h.time_sampling != 0 {
            word |= info::HAS_TIME_SAMPLING;
        }
        if h.first_changed == 0 && h.last_changed == 0 {
            word |= info::CONSTANT;
        } else if h.first_changed != 1 || h.last_changed + 1 != h.samples {
            word |= info::FIRST_LAST;
            first_last = true;
        }
    }
    push_u32(out, word);
    if h.kind != Kind::Compound {
        push_u32(out, h.samples);
        if first_last {
            push_u32(out, h.first_changed);
            push_u32(out, h.last_changed);
        }
        if h.time_sampling != 0 {
            push_u32(out, h.time_sampling);
        }
    }
    push_u32(out, h.name.len() as u32);
    out.extend_from_slice(h.name.as_bytes());
    if metadata_index == INLINE_METADATA {
        push_u32(out, h.metadata.len() as u32);
        out.extend_from_slice(h.metadata.as_bytes());
    }
}

/// Appends one object header: name and inline metadata.
pub(crate) fn push_object_header(out: &mut Vec<u8>, name: &str, metadata: &str) {
    push_u32(out, name.len() as u32);
    out.extend_from_slice(name.as_bytes());
    if metadata.is_empty() {
        out.push(NO_METADATA as u8);
    } else {
        out.push(INLINE_METADATA as u8);
        push_u32(out, metadata.len() as u32);
        out.extend_from_slice(metadata.as_bytes());
    }
}

/// Appends a little-endian `u32`.
pub(crate) fn push_u32(out: &mut Vec<u8>, v: u32) {
    out.extend_from_slice(&v.to_le_bytes());
}
