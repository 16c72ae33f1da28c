//! OBJ files by the folder: sequences (one file per frame) and the pieces of a folder.

use std::path::{Path, PathBuf};

use anim::{Mesh, MeshAnimation};

use super::{read, write, FORMAT};
use crate::{IoError, Result};

/// The files of an OBJ sequence, starting at `first`.
///
/// The frame number is the trailing run of digits of `first`'s file stem (`walk_0001.obj` →
/// `0001`); the following files are found by incrementing it with the same zero-padded width
/// (`walk_0002.obj`, …) until one is missing.
///
/// # Errors
/// [`IoError::Io`] when `first` does not exist; [`IoError::Unsupported`] when its name has
/// no trailing frame number.
pub fn sequence_paths(first: &Path) -> Result<Vec<PathBuf>> {
    std::fs::metadata(first).map_err(|e| IoError::io(first, e))?;
    let stem = first.file_stem().and_then(|s| s.to_str()).unwrap_or("");
    let digits = stem.bytes().rev().take_while(u8::is_ascii_digit).count();
    let prefix = &stem[..stem.len() - digits];
    let number: Option<u64> = stem[prefix.len()..].parse().ok();
    let Some(number) = number else {
        return Err(IoError::unsupported(
            "the file name has no trailing frame number (expected e.g. name_0001.obj)",
        )
        .at(first));
    };
    let ext = first
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    let mut paths = vec![first.to_path_buf()];
    for k in number.saturating_add(1).. {
        let p = first.with_file_name(format!("{prefix}{k:0digits$}{ext}"));
        if !p.is_file() {
            break;
        }
        paths.push(p);
    }
    Ok(paths)
}

/// Reads an OBJ sequence into a point cache.
///
/// # Arguments
/// * `paths` – one file per frame, in order (see [`sequence_paths`]).
/// * `fps` – frames per second of the sequence.
///
/// # Returns
/// A cache whose mesh (topology, attributes, rest positions) is the first file's.
///
/// # Errors
/// Any read or parse error (with the path attached), an empty list, or a file whose vertex
/// count or triangles differ from the first file's.
pub fn read_sequence(paths: &[PathBuf], fps: f32) -> Result<MeshAnimation> {
    let Some(first_path) = paths.first() else {
        return Err(IoError::unsupported("no OBJ file given for the sequence"));
    };
    let load = |p: &Path| {
        crate::read_file(p)
            .and_then(|b| read(&b))
            .map_err(|e| e.at(p))
    };
    let first = load(first_path)?;
    let mut positions = Vec::with_capacity(first.positions.len() * paths.len());
    positions.extend_from_slice(&first.positions);
    for p in &paths[1..] {
        let m = load(p)?;
        if m.vertex_count() != first.vertex_count() {
            return Err(IoError::malformed(
                FORMAT,
                format!(
                    "frame has {} vertices but the first frame ({}) has {}",
                    m.vertex_count(),
                    first_path.display(),
                    first.vertex_count()
                ),
            )
            .at(p));
        }
        if m.triangles != first.triangles {
            return Err(IoError::malformed(
                FORMAT,
                format!(
                    "faces differ from the first frame ({})",
                    first_path.display()
                ),
            )
            .at(p));
        }
        positions.extend_from_slice(&m.positions);
    }
    Ok(MeshAnimation::new(first, fps, positions)?)
}

/// Renders every frame of a cache as OBJ text, named `<base>_0001.obj`, `<base>_0002.obj`, …
/// (1-based, at least 4 digits; a `.obj` extension on `base` is dropped).
///
/// Normals are written only for a one-frame cache: the rest normals are wrong once the mesh
/// deforms. The caller writes each file with [`crate::write_atomic`].
pub fn write_sequence(anim: &MeshAnimation, base: &Path) -> Vec<(PathBuf, String)> {
    let base = match base.extension() {
        Some(e) if e.eq_ignore_ascii_case("obj") => base.with_extension(""),
        _ => base.to_path_buf(),
    };
    let stem = base
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let stem = if stem.is_empty() {
        "frame".to_string()
    } else {
        stem
    };
    let frames = anim.frame_count();
    (0..frames)
        .map(|f| {
            let mut m = anim.mesh_at(f);
            if frames > 1 {
                m.normals = None;
            }
            (
                base.with_file_name(format!("{stem}_{:04}.obj", f + 1)),
                write(&m),
            )
        })
        .collect()
}

/// The `.obj` files of the folder `dir` whose stem (file name without `.obj`) `keep`
/// accepts, read through [`read_file`](crate::read_file), as `(stem, mesh)` in file-name
/// order.
///
/// # Errors
/// The folder cannot be listed, or a kept file cannot be read or is not valid OBJ.
pub fn read_folder(dir: &Path, keep: impl Fn(&str) -> bool) -> Result<Vec<(String, Mesh)>> {
    let mut files: Vec<(String, PathBuf)> = std::fs::read_dir(dir)
        .map_err(|e| IoError::io(dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "obj"))
        .filter_map(|p| {
            let stem = p.file_stem()?.to_str()?.to_string();
            keep(&stem).then_some((stem, p))
        })
        .collect();
    files.sort_by(|a, b| a.1.cmp(&b.1));
    files
        .into_iter()
        .map(|(stem, p)| {
            let mesh = read(&crate::read_file(&p)?).map_err(|e| e.at(&p))?;
            Ok((stem, mesh))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn sequence_round_trip_on_disk() {
        let dir = tempfile::tempdir().unwrap();
        let tri = read(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        let pos: Vec<Vec3> = (0..3)
            .flat_map(|f| tri.positions.iter().map(move |p| *p * (1.0 + f as f32)))
            .collect();
        let a = MeshAnimation::new(tri, 12.0, pos).unwrap();
        let files = write_sequence(&a, &dir.path().join("walk.obj"));
        assert_eq!(files[2].0.file_name().unwrap(), "walk_0003.obj");
        for (p, text) in &files {
            crate::write_atomic(p, text.as_bytes()).unwrap();
        }
        let paths = sequence_paths(&files[0].0).unwrap();
        assert_eq!(paths.len(), 3);
        let b = read_sequence(&paths, 12.0).unwrap();
        assert_eq!(b.positions(), a.positions());
        assert!(sequence_paths(&dir.path().join("walk_0009.obj")).is_err());
        crate::write_atomic(&dir.path().join("nonum.obj"), b"v 0 0 0\n").unwrap();
        assert!(sequence_paths(&dir.path().join("nonum.obj")).is_err());
    }
}
