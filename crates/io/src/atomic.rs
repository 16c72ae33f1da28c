//! Atomic output: write to a temporary file beside the target, then rename it over the target
//! (on Linux, exchange the two names and remove the previous file).
//!
//! What is guaranteed: a reader never sees a half-written file (the rename or exchange is
//! atomic), and a failed write (full disk, size limit, error while encoding) removes the
//! temporary file and leaves any previous file as it was.
//!
//! What is not, by default: durability across a power loss or an OS crash. The temporary
//! file is not `fsync`ed before the rename, so after such a crash the target may hold the
//! previous file, the new one, or — on file systems that do not order the rename after the
//! data (e.g. ext4 without a journal, XFS; and ext4 in any mode for a replaced file on Linux,
//! whose names are exchanged: see `swapped_into_place`) — an empty or partial file. This is
//! what `numpy.save` and most DCC exporters do; the sync cost 1.2–1.8 ms per file on the
//! benchmark VM, a tenth of a whole `toonkit smear offsets` run (issue #14). Set the
//! environment variable [`SYNC_ENV`] (`TOONKIT_FSYNC=1`) to sync every file before its rename,
//! as before: then a crash leaves the previous file or the new one, complete.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::{IoError, Result};

/// Environment variable that makes every atomic write durable: when set (to anything but
/// `0`), each temporary file is synced to disk before it is renamed over its target.
pub const SYNC_ENV: &str = "TOONKIT_FSYNC";

/// Whether writes are synced before their rename ([`SYNC_ENV`]).
fn durable() -> bool {
    std::env::var_os(SYNC_ENV).is_some_and(|v| v != "0")
}

/// Writes `bytes` to `path` atomically: a reader never sees a half-written file, and a failed
/// write leaves any previous file untouched (durable across a crash only with [`SYNC_ENV`]:
/// see the module). Parent directories are created.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic_with(path, |f| {
        f.write_all(bytes).map_err(|e| IoError::io(path, e))
    })
}

/// [`write_atomic`] for a file written piece by piece: `write` fills the temporary file (a
/// large result is streamed to it instead of being encoded in memory first); on success it is
/// renamed over `path` (synced first with [`SYNC_ENV`]), on any error it is removed and `path`
/// is left untouched.
///
/// # Errors
/// `write`'s error (with `path` attached when it has none), or the file system's.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut fs::File) -> Result<()>,
) -> Result<()> {
    let tmp = stage_with(path, write)?;
    commit(&tmp, path)
}

/// Writes several files all or nothing: every file is first written in full to a temporary
/// file beside its target; only when all of them are written (a full disk, a size limit or an
/// unwritable folder fails here) are they renamed over their targets. A failure removes the
/// temporary files and leaves every previous file as it was.
pub fn write_atomic_all(files: &[(PathBuf, Vec<u8>)]) -> Result<()> {
    // Every target is checked before any is staged: all or nothing.
    for (path, _) in files {
        crate::inputs::check_not_input(path)?;
    }
    let mut temps = Vec::with_capacity(files.len());
    for (path, bytes) in files {
        match stage(path, bytes) {
            Ok(tmp) => temps.push(tmp),
            Err(e) => {
                for t in &temps {
                    let _ = fs::remove_file(t);
                }
                return Err(e);
            }
        }
    }
    for (k, ((path, _), tmp)) in files.iter().zip(&temps).enumerate() {
        if let Err(e) = commit(tmp, path) {
            for t in &temps[k + 1..] {
                let _ = fs::remove_file(t);
            }
            return Err(e);
        }
    }
    Ok(())
}

/// Writes `bytes` in full to the temporary file of `path` (synced to disk with [`SYNC_ENV`])
/// and returns its path; on failure nothing is left behind.
fn stage(path: &Path, bytes: &[u8]) -> Result<PathBuf> {
    stage_with(path, |f| {
        f.write_all(bytes).map_err(|e| IoError::io(path, e))
    })
}

/// [`stage`] with the contents written by `write`.
fn stage_with(path: &Path, write: impl FnOnce(&mut fs::File) -> Result<()>) -> Result<PathBuf> {
    crate::inputs::check_not_input(path)?;
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        fs::create_dir_all(dir).map_err(|e| IoError::io(dir, e))?;
    }
    if path.is_dir() {
        return Err(IoError::io(
            path,
            std::io::Error::from(std::io::ErrorKind::IsADirectory),
        ));
    }
    let tmp = temp_path(path);
    let result = (|| {
        let mut f = fs::File::create(&tmp).map_err(|e| IoError::io(path, e))?;
        write(&mut f).map_err(|e| e.at(path))?;
        if durable() {
            f.sync_all().map_err(|e| IoError::io(path, e))?;
        }
        Ok(())
    })();
    match result {
        Ok(()) => Ok(tmp),
        Err(e) => {
            let _ = fs::remove_file(&tmp);
            Err(e)
        }
    }
}

/// Puts a staged temporary file in place of its target (removing it when that fails).
fn commit(tmp: &Path, path: &Path) -> Result<()> {
    if swapped_into_place(tmp, path) {
        // `tmp` now names the previous file.
        let _ = fs::remove_file(tmp);
        return Ok(());
    }
    fs::rename(tmp, path).map_err(|e| {
        let _ = fs::remove_file(tmp);
        IoError::io(path, e)
    })
}

/// Exchanges the names of `tmp` and an existing target in one step (`renameat2` with
/// `RENAME_EXCHANGE`): readers see the old file or the new one, as with a rename. `false`
/// when there is no target or the file system cannot exchange; the caller then renames.
///
/// Why not a plain rename over the target: ext4 (by default, `auto_da_alloc`) then allocates
/// and starts writing back the new file's blocks inside the rename, and frees the old file's
/// pages there too: 1.7 ms of the 2.2 ms that saving a 2.4 MB `.npy` over a previous one took
/// on the benchmark VM (issue #14), against 0.2 ms for the exchange and the removal of the old
/// file. The price: like a fresh file, the replaced one is no longer written back early, so
/// after a crash it may be empty on ext4 too (see the module; [`SYNC_ENV`] syncs it first).
///
/// Only a regular file is exchanged: a directory (or anything else) at the target would trade
/// places with the staged file and end up under its name, where a rename fails instead.
#[cfg(target_os = "linux")]
fn swapped_into_place(tmp: &Path, path: &Path) -> bool {
    use rustix::fs::{renameat_with, RenameFlags, CWD};
    fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_file())
        && renameat_with(CWD, tmp, CWD, path, RenameFlags::EXCHANGE).is_ok()
}

/// Only Linux exchanges names in one step: elsewhere the caller renames.
#[cfg(not(target_os = "linux"))]
fn swapped_into_place(_tmp: &Path, _path: &Path) -> bool {
    false
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
    let mine = format!("{prefix}{}.", std::process::id());
    let Ok(entries) = fs::read_dir(dir) else {
        return 0;
    };
    entries
        .flatten()
        .filter(|e| {
            let n = e.file_name().to_string_lossy().into_owned();
            n.starts_with(&prefix) && n.ends_with(".tmp") && !n.starts_with(&mine)
        })
        .filter(|e| fs::remove_file(e.path()).is_ok())
        .count()
}

/// Writes started by this process: each gets its own temporary name, so writes of one target
/// from several threads at once (concurrent studio exports) never share a temporary file.
static WRITES: AtomicU64 = AtomicU64::new(0);

/// `.NAME.PID.N.tmp` beside `path`: the process id lets [`remove_stale_temps`] keep the
/// running process's files, `N` makes every write's name unique.
fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let n = WRITES.fetch_add(1, Ordering::Relaxed);
    path.with_file_name(format!(".{name}.{}.{n}.tmp", std::process::id()))
}

/// Reads a whole file, with the path in the error, and records it as read by the open job
/// (see [`ReadScope`](crate::ReadScope): no write of the job may replace it). Only regular
/// files are read: a device or a pipe named as input (`/dev/zero`) could never end.
pub fn read_file(path: &Path) -> Result<Vec<u8>> {
    let meta = fs::metadata(path).map_err(|e| IoError::io(path, e))?;
    if !meta.is_file() {
        return Err(IoError::unsupported(if meta.is_dir() {
            "is a directory: name a file"
        } else {
            "is not a regular file (a device or a pipe): name a file"
        })
        .at(path));
    }
    let bytes = fs::read(path).map_err(|e| IoError::io(path, e))?;
    crate::inputs::note_read(path);
    Ok(bytes)
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

    /// On Linux a replaced target gets the new file by exchanging names (the old contents end
    /// up under the temporary name and are removed); with no target there is nothing to
    /// exchange and the plain rename is used. Either way only the target is left, holding the
    /// new bytes, and a second hard link to the old file keeps the old bytes.
    #[test]
    fn replacing_exchanges_names_and_removes_the_previous_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.npy");
        let tmp = dir.path().join("staged");
        fs::write(&tmp, b"new").unwrap();
        assert!(!swapped_into_place(&tmp, &p), "nothing to exchange with");
        fs::write(&p, b"old").unwrap();
        let exchanged = swapped_into_place(&tmp, &p);
        assert_eq!(exchanged, cfg!(target_os = "linux"));
        if exchanged {
            assert_eq!(fs::read(&p).unwrap(), b"new");
            assert_eq!(fs::read(&tmp).unwrap(), b"old");
        }
        fs::remove_file(&tmp).ok();

        let link = dir.path().join("link.npy");
        write_atomic(&p, b"one").unwrap();
        fs::hard_link(&p, &link).unwrap();
        write_atomic(&p, b"two").unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"two");
        assert_eq!(fs::read(&link).unwrap(), b"one");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 2);
    }

    /// A directory where the output should go is an error, and stays where it is with its
    /// contents (an exchange of names would have moved it under the temporary name).
    #[test]
    fn a_directory_at_the_target_is_an_error_and_stays() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.npy");
        fs::create_dir(&p).unwrap();
        fs::write(p.join("inside.txt"), b"keep").unwrap();
        assert!(write_atomic(&p, b"new").is_err());
        assert_eq!(fs::read(p.join("inside.txt")).unwrap(), b"keep");
        assert_eq!(
            fs::read_dir(dir.path()).unwrap().count(),
            1,
            "no temporary file left"
        );
        // The exchange itself refuses (the check before staging could race).
        let tmp = dir.path().join("staged");
        fs::write(&tmp, b"new").unwrap();
        assert!(!swapped_into_place(&tmp, &p));
        assert_eq!(fs::read(p.join("inside.txt")).unwrap(), b"keep");
    }

    #[test]
    fn streamed_write_failing_midway_keeps_the_previous_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.npy");
        write_atomic_with(&p, |f| f.write_all(b"old").map_err(|e| IoError::io(&p, e))).unwrap();
        let err = write_atomic_with(&p, |f| {
            f.write_all(b"half").map_err(|e| IoError::io(&p, e))?;
            Err(IoError::unsupported("no more"))
        })
        .unwrap_err();
        // The error names the target, the old file is intact and no temporary is left.
        assert!(
            err.to_string().starts_with(&p.display().to_string()),
            "{err}"
        );
        assert_eq!(fs::read(&p).unwrap(), b"old");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn durable_writes_sync_and_replace_too() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.npy");
        write_atomic(&p, b"fast").unwrap();
        // Only this test sets it; others merely sync too while it is set.
        std::env::set_var(SYNC_ENV, "1");
        assert!(durable());
        let synced = write_atomic(&p, b"durable");
        std::env::remove_var(SYNC_ENV);
        synced.unwrap();
        assert!(!durable());
        assert_eq!(fs::read(&p).unwrap(), b"durable");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    /// Sixteen threads writing one name at once all succeed (each write has its own
    /// temporary file) and the target holds one of their files whole.
    #[test]
    fn concurrent_writes_of_one_name_all_succeed() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("export.glb");
        let contents: Vec<Vec<u8>> = (0..16u8).map(|k| vec![k; 64 * 1024]).collect();
        std::thread::scope(|s| {
            let handles: Vec<_> = contents
                .iter()
                .map(|c| s.spawn(|| write_atomic(&p, c)))
                .collect();
            for h in handles {
                h.join().unwrap().unwrap();
            }
        });
        let got = fs::read(&p).unwrap();
        assert!(contents.contains(&got), "a whole file of one writer");
        assert_eq!(
            fs::read_dir(dir.path()).unwrap().count(),
            1,
            "no temporary left"
        );
    }

    /// A write over a file the open job read is refused before anything is written, naming
    /// both paths; the input keeps every byte.
    #[test]
    fn writing_over_an_input_is_refused_and_the_input_is_kept() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("spot.obj");
        fs::write(&input, b"v 0 0 0\n").unwrap();
        let scope = crate::ReadScope::open();
        read_file(&input).unwrap();
        let other = dir.path().join("spot.pc2");
        let e = write_atomic_all(&[
            (other.clone(), b"cache".to_vec()),
            (input.clone(), b"rest".to_vec()),
        ])
        .unwrap_err();
        assert!(matches!(e, IoError::WouldOverwriteInput { .. }), "{e}");
        assert!(e.to_string().contains("name another output file"), "{e}");
        assert_eq!(fs::read(&input).unwrap(), b"v 0 0 0\n");
        assert!(!other.exists(), "all or nothing");
        drop(scope);
    }

    #[test]
    fn a_device_is_not_read_as_an_input() {
        let e = read_file(Path::new("/dev/zero")).unwrap_err().to_string();
        assert!(e.contains("not a regular file"), "{e}");
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
