//! Accessor values as floats, whatever their component type: FLOAT, or the integer types
//! `KHR_mesh_quantization` allows for positions, normals, texture coordinates and morph
//! deltas (BYTE, UNSIGNED_BYTE, SHORT, UNSIGNED_SHORT, normalized or not).
//!
//! Normalized integers map to [0, 1] (unsigned) or [−1, 1] (signed) as glTF 2.0 §3.11
//! defines; plain integers are converted as they are (the node transform that
//! `KHR_mesh_quantization` puts above the mesh scales them back). Sparse accessors are read
//! through the `gltf` crate's iterator, which applies the substitutions.

use gltf::accessor::{DataType, Dimensions, Item, Iter};

use crate::{IoError, Result};

/// One integer or float component converted to `f32` (normalized or not).
trait Component: Item + Copy {
    fn to_f32(self, normalized: bool) -> f32;
}

macro_rules! component {
    ($t:ty, unsigned $max:expr) => {
        impl Component for $t {
            fn to_f32(self, normalized: bool) -> f32 {
                if normalized {
                    self as f32 / $max
                } else {
                    self as f32
                }
            }
        }
    };
    ($t:ty, signed $max:expr) => {
        impl Component for $t {
            fn to_f32(self, normalized: bool) -> f32 {
                if normalized {
                    (self as f32 / $max).max(-1.0)
                } else {
                    self as f32
                }
            }
        }
    };
}
component!(u8, unsigned 255.0);
component!(u16, unsigned 65535.0);
component!(u32, unsigned 4294967295.0);
component!(i8, signed 127.0);
component!(i16, signed 32767.0);

impl Component for f32 {
    fn to_f32(self, _: bool) -> f32 {
        self
    }
}

fn outside(acc: &gltf::Accessor, what: &str) -> IoError {
    IoError::malformed(
        "glTF",
        format!("accessor {} ({what}) lies outside its buffer", acc.index()),
    )
}

/// The elements of an accessor of `kind` components whose data lie tightly packed in its
/// buffer view (no gap between elements, not sparse), decoded straight from the bytes: the items `gltf`'s
/// iterator yields, without its per-item bookkeeping (most of the cost of reading a mesh).
/// `None` for another component type, any other layout, or data outside the buffer: the
/// caller then reads through the iterator, which handles every case and reports the errors.
pub(crate) fn packed<T: Item>(
    acc: &gltf::Accessor,
    buffers: &[&[u8]],
    kind: DataType,
) -> Option<Vec<T>> {
    let size = std::mem::size_of::<T>();
    if acc.data_type() != kind || acc.sparse().is_some() || acc.size() != size {
        return None;
    }
    let view = acc.view()?;
    if view.stride().is_some_and(|s| s != size) {
        return None;
    }
    let len = acc.count().checked_mul(size)?;
    if acc.offset().checked_add(len)? > view.length() {
        return None;
    }
    let start = view.offset().checked_add(acc.offset())?;
    let bytes = buffers
        .get(view.buffer().index())?
        .get(start..start.checked_add(len)?)?;
    Some(bytes.chunks_exact(size).map(T::from_slice).collect())
}

macro_rules! reader {
    ($name:ident, $n:literal) => {
        fn $name<T: Component>(
            acc: &gltf::Accessor,
            buffers: &[&[u8]],
            what: &str,
        ) -> Result<Vec<[f32; $n]>>
        where
            [T; $n]: Item,
        {
            let norm = acc.normalized();
            if let Some(items) = packed::<[T; $n]>(acc, buffers, acc.data_type()) {
                return Ok(items
                    .into_iter()
                    .map(|v| v.map(|c| c.to_f32(norm)))
                    .collect());
            }
            let iter = Iter::<[T; $n]>::new(acc.clone(), |b: gltf::Buffer| {
                buffers.get(b.index()).copied()
            })
            .ok_or_else(|| outside(acc, what))?;
            Ok(iter.map(|v| v.map(|c| c.to_f32(norm))).collect())
        }
    };
}
reader!(read2, 2);
reader!(read3, 3);

macro_rules! dispatch {
    ($name:ident, $inner:ident, $n:literal, $dims:expr) => {
        /// The accessor's elements as floats; `what` names it in errors.
        ///
        /// # Errors
        /// When the accessor has another element type, its data lies outside its buffer,
        /// or it is neither in a buffer view nor sparse.
        pub(crate) fn $name(
            acc: &gltf::Accessor,
            buffers: &[&[u8]],
            what: &str,
        ) -> Result<Vec<[f32; $n]>> {
            if acc.dimensions() != $dims {
                return Err(IoError::malformed(
                    "glTF",
                    format!(
                        "accessor {} ({what}) is {:?}, expected {:?}",
                        acc.index(),
                        acc.dimensions(),
                        $dims
                    ),
                ));
            }
            if acc.count() == 0 {
                return Ok(Vec::new());
            }
            match acc.data_type() {
                DataType::F32 => $inner::<f32>(acc, buffers, what),
                DataType::U8 => $inner::<u8>(acc, buffers, what),
                DataType::U16 => $inner::<u16>(acc, buffers, what),
                DataType::U32 => $inner::<u32>(acc, buffers, what),
                DataType::I8 => $inner::<i8>(acc, buffers, what),
                DataType::I16 => $inner::<i16>(acc, buffers, what),
            }
        }
    };
}
dispatch!(vec2s, read2, 2, Dimensions::Vec2);
dispatch!(vec3s, read3, 3, Dimensions::Vec3);

#[cfg(test)]
mod tests {
    use super::*;

    fn iterated<T: Item>(acc: &gltf::Accessor, buffers: &[&[u8]]) -> Vec<T> {
        Iter::<T>::new(acc.clone(), |b: gltf::Buffer| {
            buffers.get(b.index()).copied()
        })
        .expect("in its buffer")
        .collect()
    }

    /// Every tightly packed accessor of a real character reads the same through [`packed`]
    /// as through `gltf`'s iterator (positions, normals, joints, weights, indices, times).
    #[test]
    fn packed_accessors_read_as_iterated() {
        let path = testdata::asset("characters/RobotExpressive.glb");
        let (doc, buffers, _) = gltf::import(path).unwrap();
        let buffers: Vec<&[u8]> = buffers.iter().map(|b| &b[..]).collect();
        let mut checked = 0;
        for acc in doc.accessors() {
            let same = match (acc.data_type(), acc.dimensions()) {
                (DataType::F32, Dimensions::Vec3) => {
                    packed::<[f32; 3]>(&acc, &buffers, DataType::F32)
                        .map(|p| p == iterated::<[f32; 3]>(&acc, &buffers))
                }
                (DataType::F32, Dimensions::Vec4) => {
                    packed::<[f32; 4]>(&acc, &buffers, DataType::F32)
                        .map(|p| p == iterated::<[f32; 4]>(&acc, &buffers))
                }
                (DataType::F32, Dimensions::Scalar) => packed::<f32>(&acc, &buffers, DataType::F32)
                    .map(|p| p == iterated::<f32>(&acc, &buffers)),
                (DataType::U16, Dimensions::Scalar) => packed::<u16>(&acc, &buffers, DataType::U16)
                    .map(|p| p == iterated::<u16>(&acc, &buffers)),
                (DataType::U8, Dimensions::Vec4) => packed::<[u8; 4]>(&acc, &buffers, DataType::U8)
                    .map(|p| p == iterated::<[u8; 4]>(&acc, &buffers)),
                _ => None,
            };
            if let Some(same) = same {
                assert!(same, "accessor {}", acc.index());
                checked += 1;
            }
        }
        assert!(checked > 50, "only {checked} packed accessors");
        // A layout it does not read (a component size that does not match) is left to the
        // iterator.
        let acc = doc.accessors().next().unwrap();
        assert!(packed::<u8>(&acc, &buffers, acc.data_type()).is_none());
        assert!(packed::<[f32; 3]>(&acc, &buffers, DataType::U32).is_none());
    }
}
