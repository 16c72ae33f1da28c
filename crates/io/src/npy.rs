//! NumPy `.npy` arrays of floats (format versions 1.0–3.0).
//!
//! [`write_f32`] writes version 1.0, `'<f4'`, C order, with the header padded by spaces and a
//! final newline so that the data starts at a multiple of 64 bytes, as the NumPy format
//! specification asks. [`read_f32`] accepts what `numpy.save` writes for float arrays:
//! versions 1.0, 2.0 and 3.0, `f4` or `f8` in either byte order (`f8` is converted to `f32`,
//! since `numpy.save` keeps float64 unless told otherwise), C or Fortran order (returned in C
//! order).

use crate::{IoError, Result};

const FORMAT: &str = "NPY";
/// The 6-byte magic at the start of every NPY file.
pub const MAGIC: &[u8; 6] = b"\x93NUMPY";
/// Alignment of the data start required by the NumPy format specification.
pub const ALIGNMENT: usize = 64;

/// Writes a float32 array.
///
/// # Arguments
/// * `shape` – dimensions, C order (last index fastest); `&[]` is a scalar.
/// * `data` – the values; its length must be the product of `shape`.
///
/// # Errors
/// [`IoError::Unsupported`] when `data.len()` is not the product of `shape`.
pub fn write_f32(shape: &[usize], data: &[f32]) -> Result<Vec<u8>> {
    let mut out = header_f32(shape, data.len())?;
    out.reserve_exact(4 * data.len());
    for v in data {
        out.extend_from_slice(&v.to_le_bytes());
    }
    Ok(out)
}

/// Values per block of [`write_f32_to`]: 64 KiB of bytes, converted in cache and written.
const BLOCK: usize = 16 * 1024;

/// Writes the float32 array of [`write_f32`] (the same bytes) to `w` without encoding the whole
/// file in memory first: on a little-endian machine the values themselves, elsewhere block by
/// block as they are converted (no second copy of a result of megabytes, and no fresh pages
/// for one).
///
/// # Errors
/// [`IoError::Unsupported`] when `data.len()` is not the product of `shape`; the first write
/// error of `w` as [`IoError::Io`] (without a path: the caller knows it).
pub fn write_f32_to(w: &mut impl std::io::Write, shape: &[usize], data: &[f32]) -> Result<()> {
    let header = header_f32(shape, data.len())?;
    let io = |e| IoError::io(std::path::Path::new(""), e);
    w.write_all(&header).map_err(io)?;
    // On a little-endian machine the values in memory are the file's bytes: written as they
    // are, in one call (no conversion pass, no copy).
    if cfg!(target_endian = "little") {
        return w.write_all(bytemuck::cast_slice(data)).map_err(io);
    }
    let mut block = vec![0u8; 4 * BLOCK.min(data.len())];
    for chunk in data.chunks(BLOCK) {
        // Fixed-size stores into a sized block: a plain copy on little-endian machines.
        let bytes = &mut block[..4 * chunk.len()];
        for (b, v) in bytes.chunks_exact_mut(4).zip(chunk) {
            b.copy_from_slice(&v.to_le_bytes());
        }
        w.write_all(bytes).map_err(io)?;
    }
    Ok(())
}

/// The NPY 1.0 header (magic, version, length, dictionary) of a float32 array of `shape`
/// holding `len` values.
///
/// # Errors
/// [`IoError::Unsupported`] when `len` is not the product of `shape`, or the header does not
/// fit NPY 1.0.
fn header_f32(shape: &[usize], len: usize) -> Result<Vec<u8>> {
    let count = shape.iter().try_fold(1usize, |a, &d| a.checked_mul(d));
    if count != Some(len) {
        return Err(IoError::unsupported(format!(
            "array of shape {shape:?} needs {} values, got {len}",
            count.map_or_else(|| "more than 2^64".to_string(), |c| c.to_string()),
        )));
    }
    let dims = match shape {
        [d] => format!("({d},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|d| d.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let mut header = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {dims}, }}");
    // magic(6) + version(2) + header length(2) + header + '\n' ≡ 0 (mod 64)
    let unpadded = 10 + header.len() + 1;
    let pad = (ALIGNMENT - unpadded % ALIGNMENT) % ALIGNMENT;
    header.extend(std::iter::repeat_n(' ', pad));
    header.push('\n');
    let header_len = u16::try_from(header.len())
        .map_err(|_| IoError::unsupported("array has too many dimensions for NPY 1.0"))?;
    let mut out = Vec::with_capacity(10 + header.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[1, 0]);
    out.extend_from_slice(&header_len.to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    Ok(out)
}

/// Reads a float array as `f32`, in C order.
///
/// # Returns
/// `(shape, values)` with `values.len()` = product of `shape`.
///
/// # Errors
/// [`IoError::Malformed`] for a bad magic, header or length; [`IoError::Unsupported`] for
/// element types other than `f4`/`f8`. Non-finite values are returned as they are (callers
/// decide whether NaN is meaningful).
pub fn read_f32(bytes: &[u8]) -> Result<(Vec<usize>, Vec<f32>)> {
    if bytes.len() < 10 || &bytes[..6] != MAGIC {
        return Err(IoError::malformed(FORMAT, "missing \\x93NUMPY magic"));
    }
    let (header_len, start): (usize, usize) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        v => {
            return Err(IoError::malformed(
                FORMAT,
                format!("unknown format version {v}"),
            ))
        }
    };
    let data_start = start
        .checked_add(header_len)
        .filter(|&e| e <= bytes.len())
        .ok_or_else(|| IoError::malformed(FORMAT, "header runs past the end of the file"))?;
    let header = std::str::from_utf8(&bytes[start..data_start])
        .map_err(|_| IoError::malformed(FORMAT, "header is not text"))?;
    let descr = dict_value(header, "descr")
        .ok_or_else(|| IoError::malformed(FORMAT, "header has no 'descr'"))?
        .trim_matches(|c| c == '\'' || c == '"');
    let (big_endian, width) = match descr {
        "<f4" | "=f4" => (false, 4),
        ">f4" => (true, 4),
        "<f8" | "=f8" => (false, 8),
        ">f8" => (true, 8),
        other => {
            return Err(IoError::unsupported(format!(
                "NPY element type '{other}' is not supported; save the array as float32"
            )))
        }
    };
    let fortran = match dict_value(header, "fortran_order") {
        Some("False") => false,
        Some("True") => true,
        _ => {
            return Err(IoError::malformed(
                FORMAT,
                "header has no valid 'fortran_order'",
            ))
        }
    };
    let shape = parse_shape(
        dict_value(header, "shape")
            .ok_or_else(|| IoError::malformed(FORMAT, "header has no 'shape'"))?,
    )?;
    let count = shape.iter().try_fold(1usize, |a, &d| a.checked_mul(d));
    let data = &bytes[data_start..];
    if count.and_then(|c| c.checked_mul(width)) != Some(data.len()) {
        return Err(IoError::malformed(
            FORMAT,
            format!(
                "shape {shape:?} of {width}-byte values needs {} data bytes, the file has {}",
                count
                    .and_then(|c| c.checked_mul(width))
                    .map_or_else(|| "more than 2^64".to_string(), |n| n.to_string()),
                data.len()
            ),
        ));
    }
    let values: Vec<f32> = data
        .chunks_exact(width)
        .map(|c| match (width, big_endian) {
            (4, false) => f32::from_le_bytes([c[0], c[1], c[2], c[3]]),
            (4, true) => f32::from_be_bytes([c[0], c[1], c[2], c[3]]),
            (_, false) => {
                f64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]) as f32
            }
            (_, true) => {
                f64::from_be_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]) as f32
            }
        })
        .collect();
    let values = if fortran && shape.len() > 1 {
        fortran_to_c(&shape, &values)
    } else {
        values
    };
    Ok((shape, values))
}

/// The raw text of `key`'s value in a Python dict literal (up to the next top-level comma
/// or closing brace).
fn dict_value<'a>(header: &'a str, key: &str) -> Option<&'a str> {
    let at = header
        .find(&format!("'{key}'"))
        .or_else(|| header.find(&format!("\"{key}\"")))?;
    let rest = header[at + key.len() + 2..]
        .trim_start()
        .strip_prefix(':')?
        .trim_start();
    let mut depth = 0i32;
    for (i, c) in rest.char_indices() {
        match c {
            '(' | '[' => depth += 1,
            ')' | ']' => {
                depth -= 1;
                if depth == 0 {
                    return Some(rest[..=i].trim());
                }
            }
            ',' | '}' if depth == 0 => return Some(rest[..i].trim()),
            _ => {}
        }
    }
    None
}

fn parse_shape(text: &str) -> Result<Vec<usize>> {
    let inner = text
        .strip_prefix('(')
        .and_then(|t| t.strip_suffix(')'))
        .ok_or_else(|| IoError::malformed(FORMAT, format!("shape '{text}' is not a tuple")))?;
    inner
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.trim_end_matches('L')
                .parse::<usize>()
                .map_err(|_| IoError::malformed(FORMAT, format!("bad dimension '{s}' in shape")))
        })
        .collect()
}

/// Reorders Fortran-order (first index fastest) values to C order.
fn fortran_to_c(shape: &[usize], values: &[f32]) -> Vec<f32> {
    let n = shape.len();
    let mut f_strides = vec![1usize; n];
    for d in 1..n {
        f_strides[d] = f_strides[d - 1] * shape[d - 1];
    }
    let mut out = Vec::with_capacity(values.len());
    let mut idx = vec![0usize; n];
    for _ in 0..values.len() {
        let src: usize = idx.iter().zip(&f_strides).map(|(i, s)| i * s).sum();
        out.push(values[src]);
        for d in (0..n).rev() {
            idx[d] += 1;
            if idx[d] < shape[d] {
                break;
            }
            idx[d] = 0;
        }
    }
    out
}

/// One `f32` per vertex from the `.npy` at `path`: a float array of shape `(vertices,)` or
/// `(1, vertices)` (per-vertex weights such as a saliency map), read through
/// [`read_file`](crate::read_file).
///
/// # Errors
/// The read, [`read_f32`]'s errors, or [`IoError::Unsupported`] for another shape (the
/// message gives the shape found and the one expected).
pub fn read_per_vertex(path: &std::path::Path) -> Result<Vec<f32>> {
    let bytes = crate::read_file(path)?;
    let (shape, values) = read_f32(&bytes).map_err(|e| e.at(path))?;
    if !matches!(shape.as_slice(), [_] | [1, _]) {
        return Err(IoError::unsupported(format!(
            "shape {shape:?}, expected (vertices,) or (1, vertices) (one weight per vertex)"
        ))
        .at(path));
    }
    Ok(values)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_is_aligned_and_round_trips() {
        for shape in [vec![], vec![5], vec![2, 3], vec![2, 1, 2]] {
            let n: usize = shape.iter().product();
            let data: Vec<f32> = (0..n).map(|i| i as f32 * 0.5 - 1.0).collect();
            let bytes = write_f32(&shape, &data).unwrap();
            let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
            assert!((10 + header_len).is_multiple_of(64));
            assert_eq!(bytes[10 + header_len - 1], b'\n');
            assert_eq!(read_f32(&bytes).unwrap(), (shape, data));
        }
    }

    /// The streamed writer gives the bytes of the in-memory one, across block boundaries,
    /// and refuses a shape that does not match before writing anything.
    #[test]
    fn streamed_array_has_the_same_bytes() {
        // Two whole blocks and a partial one.
        let m = BLOCK - BLOCK / 3 + 5;
        let data: Vec<f32> = (0..3 * m).map(|i| (i as f32).sin()).collect();
        let mut streamed = Vec::new();
        write_f32_to(&mut streamed, &[3, m], &data).unwrap();
        assert_eq!(streamed, write_f32(&[3, m], &data).unwrap());
        let mut none = Vec::new();
        assert!(write_f32_to(&mut none, &[2, 2], &data).is_err());
        assert!(none.is_empty());
    }

    fn with_header(header: &str, data: &[u8]) -> Vec<u8> {
        let mut bytes = MAGIC.to_vec();
        bytes.extend_from_slice(&[1, 0]);
        bytes.extend_from_slice(&(header.len() as u16).to_le_bytes());
        bytes.extend_from_slice(header.as_bytes());
        bytes.extend_from_slice(data);
        bytes
    }

    #[test]
    fn numpy_float64_fortran_file_is_read() {
        // np.save(f, np.asfortranarray(np.arange(6, dtype='>f8').reshape(2, 3)))
        // Fortran order of [[0,1,2],[3,4,5]] is 0,3,1,4,2,5.
        let data: Vec<u8> = [0.0f64, 3.0, 1.0, 4.0, 2.0, 5.0]
            .iter()
            .flat_map(|v| v.to_be_bytes())
            .collect();
        let bytes = with_header(
            "{'descr': '>f8', 'fortran_order': True, 'shape': (2, 3), }",
            &data,
        );
        let (shape, values) = read_f32(&bytes).unwrap();
        assert_eq!(shape, vec![2, 3]);
        assert_eq!(values, vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
    }

    #[test]
    fn corrupt_inputs_are_errors() {
        let bytes = write_f32(&[2, 2], &[1.0, 2.0, 3.0, 4.0]).unwrap();
        assert!(read_f32(&bytes[..bytes.len() - 1]).is_err());
        assert!(read_f32(&bytes[..20]).is_err());
        assert!(read_f32(b"\x93NUMPZ\x01\x00\x00\x00").is_err());
        let data = &bytes[64..];
        let huge = "{'descr': '<f4', 'fortran_order': False, 'shape': (9999999999, 99999), }";
        let e = read_f32(&with_header(huge, data)).unwrap_err().to_string();
        assert!(e.contains("needs"), "{e}");
        let overflow =
            "{'descr': '<f4', 'fortran_order': False, 'shape': (4294967296, 4294967296), }";
        assert!(read_f32(&with_header(overflow, data)).is_err());
        let ints = "{'descr': '<i4', 'fortran_order': False, 'shape': (2, 2), }";
        assert!(matches!(
            read_f32(&with_header(ints, data)),
            Err(IoError::Unsupported { .. })
        ));
        let no_shape = "{'descr': '<f4', 'fortran_order': False, }";
        assert!(read_f32(&with_header(no_shape, data)).is_err());
        assert!(write_f32(&[3], &[1.0]).is_err());
    }
}
