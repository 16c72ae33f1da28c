//! A fix-up of the crate files `openusd` 0.6 writes: it stores `primChildren` and
//! `propertyChildren` as token *arrays* (`VtArray<TfToken>`), where Pixar's USD expects the
//! `TokenVector` type (`std::vector<TfToken>`) and refuses the layer ("Invalid children found in
//! primChildren field"). Both have the same bytes on the value heap (a `u64` count, then `u32`
//! token indices), so only the type of their value representations changes: the `FIELDS`
//! section is rewritten with every token-array representation retyped as `TokenVector` (toonkit
//! writes no other token array), and the sections after it and the table of contents are moved
//! by the size difference. Newer `openusd` releases (which need Rust ≥ 1.96) are not used.
//!
//! The file is also labelled crate version 0.8.0 (Pixar's default for new files), as the
//! layout it uses needs (64-bit array sizes since 0.7.0; no newer value type is written):
//! `openusd` labels it 0.12.0, which the USD 24.x inside Blender 4.2 refuses to open.

use crate::{IoError, Result};

/// Crate file version written: major, minor, patch.
const CRATE_VERSION: [u8; 3] = [0, 8, 0];
/// Crate value types (Pixar's `TypeEnum`).
const TOKEN: u64 = 11;
const TOKEN_VECTOR: u64 = 41;
const ARRAY_BIT: u64 = 1 << 63;
const TYPE_SHIFT: u32 = 48;
const TYPE_MASK: u64 = 0xff << TYPE_SHIFT;

/// Retypes the children lists of a crate file written by `openusd` (see the module
/// documentation).
pub(crate) fn retype_children(bytes: Vec<u8>) -> Result<Vec<u8>> {
    let u64_at = |b: &[u8], at: usize| -> Result<u64> {
        b.get(at..at + 8)
            .map(|s| u64::from_le_bytes(s.try_into().unwrap_or_default()))
            .ok_or_else(|| bad("offset past the end"))
    };
    let toc = u64_at(&bytes, 16)? as usize;
    let count = u64_at(&bytes, toc)? as usize;
    // (name, start, size) of every section.
    let mut sections = Vec::with_capacity(count);
    for k in 0..count.min(64) {
        let at = toc + 8 + k * 32;
        let name = bytes
            .get(at..at + 16)
            .ok_or_else(|| bad("truncated table of contents"))?;
        let name = String::from_utf8_lossy(name)
            .trim_end_matches('\0')
            .to_string();
        sections.push((
            name,
            u64_at(&bytes, at + 16)? as usize,
            u64_at(&bytes, at + 24)? as usize,
        ));
    }
    let Some(&(_, start, size)) = sections.iter().find(|(n, _, _)| n == "FIELDS") else {
        return Err(bad("no FIELDS section"));
    };
    // FIELDS: field count, compressed token indices (size + bytes), compressed value reps.
    let fields = u64_at(&bytes, start)? as usize;
    let tokens_size = u64_at(&bytes, start + 8)? as usize;
    let reps_at = start + 16 + tokens_size;
    let reps_size = u64_at(&bytes, reps_at)? as usize;
    let block = bytes
        .get(reps_at + 8..reps_at + 8 + reps_size)
        .filter(|b| b.first() == Some(&0))
        .ok_or_else(|| bad("unexpected value representation block"))?;
    let mut reps = lz4_flex::block::decompress(&block[1..], fields * 8)
        .map_err(|e| IoError::encode("USD", e))?;
    for rep in reps.chunks_exact_mut(8) {
        let v = u64::from_le_bytes(rep.try_into().unwrap_or_default());
        if v & ARRAY_BIT != 0 && (v & TYPE_MASK) >> TYPE_SHIFT == TOKEN {
            let fixed = (v & !ARRAY_BIT & !TYPE_MASK) | (TOKEN_VECTOR << TYPE_SHIFT);
            rep.copy_from_slice(&fixed.to_le_bytes());
        }
    }
    let mut new_block = vec![0u8];
    new_block.extend_from_slice(&lz4_flex::block::compress(&reps));
    let mut section = bytes[start..reps_at].to_vec();
    section.extend_from_slice(&(new_block.len() as u64).to_le_bytes());
    section.extend_from_slice(&new_block);
    let end = start + size;
    let delta = section.len() as i64 - size as i64;
    let shift = |at: usize| {
        if at >= end {
            (at as i64 + delta) as usize
        } else {
            at
        }
    };

    let mut out = Vec::with_capacity(bytes.len() + section.len());
    out.extend_from_slice(&bytes[..start]);
    out.extend_from_slice(&section);
    out.extend_from_slice(&bytes[end..toc]);
    let new_toc = out.len();
    out.extend_from_slice(&(sections.len() as u64).to_le_bytes());
    for (name, s, z) in &sections {
        let mut n = [0u8; 16];
        let b = name.as_bytes();
        n[..b.len().min(15)].copy_from_slice(&b[..b.len().min(15)]);
        out.extend_from_slice(&n);
        let size = if *s == start { section.len() } else { *z };
        out.extend_from_slice(&(shift(*s) as u64).to_le_bytes());
        out.extend_from_slice(&(size as u64).to_le_bytes());
    }
    out[16..24].copy_from_slice(&(new_toc as u64).to_le_bytes());
    out[8..11].copy_from_slice(&CRATE_VERSION);
    Ok(out)
}

fn bad(message: &str) -> IoError {
    IoError::encode(
        "USD",
        format!("unexpected crate layout from openusd: {message}"),
    )
}
