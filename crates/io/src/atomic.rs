//! Atomic output: write to a temporary file beside the target, then rename.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::{IoError, Result};

/// Writes `bytes` to `path` atomically: a reader never sees a half-written file, and a failed
/// write leaves any previous file untouched. Parent directories are created.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        fs::create_dir_all(dir).map_err(|e| IoError::io(dir, e))?;
    }
    let tmp = temp_path(path);
    let result = (|| {
        let mut f = fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        let _ = fs::remove_file(&tmp);
        return Err(IoError::io(path, e));
    }
    Ok(())
}

/// Removes the temporary files that interrupted [`write_atomic`] calls of `path` left beside
/// it (a killed process cannot clean up after itself; the target itself is never touched).
/// Temporary files of the running process are kept. Returns how many were removed.
pub fn remove_stale_temps(path: &Path) -> usize {
    let (Some(dir), Some(name)) = (path.parent(), path.file_name()) else {
        return 0;
    };
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let prefix = format!(".{}.", name.to_string_lossy());
    let mine = temp_path(path);
    let Ok(entries) = fs::read_dir(dir) else {
        return 0;
    };
    entries
        .flatten()
        .filter(|e| {
            let n = e.file_name().to_string_lossy().into_owned();
            n.starts_with(&prefix) && n.ends_with(".tmp") && e.path() != mine
        })
        .filter(|e| fs::remove_file(e.path()).is_ok())
        .count()
}

fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

/// Reads a whole file, with the path in the error.
pub fn read_file(path: &Path) -> Result<Vec<u8>> {
    fs::read(path).map_err(|e| IoError::io(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_replaces_and_leaves_no_temp() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("sub/out.bin");
        write_atomic(&p, b"one").unwrap();
        write_atomic(&p, b"two").unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"two");
        let names: Vec<_> = fs::read_dir(p.parent().unwrap()).unwrap().collect();
        assert_eq!(names.len(), 1);
    }

    #[test]
    fn stale_temps_of_a_killed_writer_are_removed() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.abc");
        write_atomic(&p, b"done").unwrap();
        fs::write(dir.path().join(".out.abc.999999.tmp"), b"partial").unwrap();
        fs::write(dir.path().join(".other.abc.999999.tmp"), b"not ours").unwrap();
        assert_eq!(remove_stale_temps(&p), 1);
        assert_eq!(fs::read(&p).unwrap(), b"done");
        assert!(dir.path().join(".other.abc.999999.tmp").exists());
    }
}
