//! Application-specific scalar vertex attributes (glTF 2.0 §3.7.2.1: semantic names starting
//! with `_`, e.g. `_SMEAR_WEIGHT` painted in Blender or Maya) ↔ [`anim::Mesh::attributes`].
//!
//! Reading: every SCALAR `_` attribute of a primitive becomes one entry named with its
//! underscore; FLOAT is taken as is, normalized integers are mapped to [0, 1] (unsigned) or
//! [−1, 1] (signed) as the glTF spec defines, plain integers are converted to float.
//! Non-scalar `_` attributes are skipped (they are not painted weights). Writing: every entry
//! is a FLOAT SCALAR attribute; a name without a leading `_` gets one.

use std::collections::BTreeMap;

use anim::Mesh;
use gltf::accessor::{DataType, Dimensions, Item, Iter};
use gltf_json as json;
use json::mesh::Semantic;

use crate::gltf::accessors::{Builder, Usage};
use crate::{IoError, Result};

/// The glTF semantic (with its leading `_`) under which attribute `name` is written.
///
/// `"_SMEAR_WEIGHT"` stays as is, `"weight"` becomes `"_weight"` (case is kept).
pub(crate) fn gltf_name(name: &str) -> String {
    if name.starts_with('_') {
        name.to_string()
    } else {
        format!("_{name}")
    }
}

impl Builder {
    /// Accessors for every entry of `m.attributes`, FLOAT SCALAR, with their semantics.
    /// Non-finite values are written as 0.
    ///
    /// # Errors
    /// When a name is empty, two names map to the same semantic (`W` and `_W`), or an
    /// attribute does not have one value per vertex.
    pub(crate) fn scalar_attributes(
        &mut self,
        m: &Mesh,
    ) -> Result<Vec<(Semantic, json::Index<json::Accessor>)>> {
        let mut out: Vec<(Semantic, json::Index<json::Accessor>)> = Vec::new();
        let mut seen: BTreeMap<String, &str> = BTreeMap::new();
        for (name, values) in &m.attributes {
            if name.is_empty() || name == "_" {
                return Err(IoError::unsupported(format!(
                    "mesh '{}' has a vertex attribute without a name; name it",
                    m.name
                )));
            }
            let full = gltf_name(name);
            if let Some(other) = seen.insert(full.clone(), name) {
                return Err(IoError::unsupported(format!(
                    "mesh '{}': attributes '{other}' and '{name}' would both be written as \
                     {full}; rename one",
                    m.name
                )));
            }
            if values.len() != m.vertex_count() {
                return Err(IoError::unsupported(format!(
                    "mesh '{}': attribute '{name}' has {} values for {} vertices",
                    m.name,
                    values.len(),
                    m.vertex_count()
                )));
            }
            let acc = self.floats(values, 1, Usage::Vertex, false);
            out.push((Semantic::Extras(full[1..].to_string()), acc));
        }
        Ok(out)
    }
}

/// Reads the SCALAR application-specific attributes of a primitive with `n` vertices.
///
/// # Errors
/// When an accessor's count differs from `n` or its data lies outside its buffer.
pub(crate) fn read_attributes(
    prim: &gltf::Primitive,
    buffers: &[&[u8]],
    n: usize,
) -> Result<BTreeMap<String, Vec<f32>>> {
    let mut out = BTreeMap::new();
    for (semantic, acc) in prim.attributes() {
        let gltf::Semantic::Extras(name) = semantic else {
            continue;
        };
        if acc.dimensions() != Dimensions::Scalar {
            continue; // not a per-vertex scalar: not ours to interpret
        }
        let full = format!("_{name}");
        if acc.count() != n {
            return Err(IoError::malformed(
                "glTF",
                format!(
                    "accessor {} ({full}) has {} values but POSITION has {n}",
                    acc.index(),
                    acc.count()
                ),
            ));
        }
        let values = if n == 0 {
            Vec::new()
        } else {
            let norm = acc.normalized();
            match acc.data_type() {
                DataType::F32 => read::<f32>(&acc, buffers, &full, |x| x),
                DataType::U8 => read::<u8>(&acc, buffers, &full, |x| unorm(x as f32, 255.0, norm)),
                DataType::U16 => {
                    read::<u16>(&acc, buffers, &full, |x| unorm(x as f32, 65535.0, norm))
                }
                DataType::U32 => read::<u32>(&acc, buffers, &full, |x| x as f32),
                DataType::I8 => read::<i8>(&acc, buffers, &full, |x| snorm(x as f32, 127.0, norm)),
                DataType::I16 => {
                    read::<i16>(&acc, buffers, &full, |x| snorm(x as f32, 32767.0, norm))
                }
            }?
        };
        out.insert(full, values);
    }
    Ok(out)
}

/// An unsigned integer as float, divided by the type's maximum when normalized.
fn unorm(x: f32, max: f32, normalized: bool) -> f32 {
    if normalized {
        x / max
    } else {
        x
    }
}

/// A signed integer as float; normalized: `max(x / max, −1)` (glTF 2.0 §3.11).
fn snorm(x: f32, max: f32, normalized: bool) -> f32 {
    if normalized {
        (x / max).max(-1.0)
    } else {
        x
    }
}

fn read<T: Item + Copy>(
    acc: &gltf::Accessor,
    buffers: &[&[u8]],
    what: &str,
    f: impl Fn(T) -> f32,
) -> Result<Vec<f32>> {
    let it = Iter::<T>::new(acc.clone(), |b: gltf::Buffer| {
        buffers.get(b.index()).copied()
    })
    .ok_or_else(|| {
        IoError::malformed("glTF", format!("{what} accessor lies outside its buffer"))
    })?;
    Ok(it.map(f).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_get_one_leading_underscore() {
        assert_eq!(gltf_name("_SMEAR_WEIGHT"), "_SMEAR_WEIGHT");
        assert_eq!(gltf_name("weight"), "_weight");
        assert_eq!(gltf_name("__x"), "__x");
    }

    #[test]
    fn normalized_integers_map_to_unit_range() {
        assert_eq!(unorm(255.0, 255.0, true), 1.0);
        assert_eq!(unorm(255.0, 255.0, false), 255.0);
        assert_eq!(snorm(-128.0, 127.0, true), -1.0);
        assert_eq!(snorm(-32767.0, 32767.0, true), -1.0);
    }
}
