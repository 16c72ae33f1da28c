//! The files a job reads, so that no write of the job replaces one of them.
//!
//! Every reader in this crate records the files it opens ([`note_read`]: the file named, the
//! external buffers of a `.gltf`, the rest `.obj` of a point cache, the frames of an OBJ
//! sequence, style and option files read through [`read_file`](crate::read_file)) while a
//! [`ReadScope`] is open, and every atomic write ([`write_atomic`](crate::write_atomic) and
//! its siblings, hence `save`) refuses a target that is one of them. Files are
//! compared by device and inode, so a symlink, a hard link or another spelling of the path
//! (`./fox.glb`, `../o2/fox.glb`) is the same file.
//!
//! A scope is a job: the CLI opens one for its whole run, a batch for each shot (the shots
//! running at the same time see each other's inputs, so one shot cannot replace another's
//! input), the studio for its lifetime (the file it serves), the Python module for each
//! loaded scene. With no scope open nothing is recorded and nothing is refused.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

use crate::{IoError, Result};

/// The identity of a file on disk: device and inode where the OS has them.
#[derive(Debug, Clone, PartialEq, Eq)]
enum FileKey {
    #[cfg(unix)]
    Inode { dev: u64, ino: u64 },
    #[cfg(not(unix))]
    Canonical(PathBuf),
}

impl FileKey {
    /// The identity of the file `path` names (following symlinks), if it exists.
    fn of(path: &Path) -> Option<FileKey> {
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            let m = std::fs::metadata(path).ok()?;
            Some(FileKey::Inode {
                dev: m.dev(),
                ino: m.ino(),
            })
        }
        #[cfg(not(unix))]
        {
            std::fs::canonicalize(path).ok().map(FileKey::Canonical)
        }
    }
}

/// One file read by the jobs of an open scope.
struct Entry {
    scope: u64,
    key: FileKey,
    path: PathBuf,
}

/// Files read by the open scopes (few: one per running job, a handful of files each).
static READ: Mutex<Vec<Entry>> = Mutex::new(Vec::new());
/// Scopes open now, and the next scope's number.
static OPEN: Mutex<Vec<u64>> = Mutex::new(Vec::new());
static NEXT: AtomicU64 = AtomicU64::new(1);

thread_local! {
    /// Scopes opened on this thread, innermost last: a read on this thread belongs to them
    /// (a read on a thread that opened none, e.g. a parallel worker, belongs to every open
    /// scope: never missed, at worst also charged to a job that runs beside it).
    static MINE: std::cell::RefCell<Vec<u64>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// An open job: while it lives, the files read are recorded and no write may replace them.
/// Dropping it forgets its files.
#[derive(Debug)]
#[must_use = "the scope ends when dropped"]
pub struct ReadScope {
    id: u64,
}

impl ReadScope {
    /// Opens a scope (see the module).
    pub fn open() -> ReadScope {
        let id = NEXT.fetch_add(1, Ordering::Relaxed);
        lock(&OPEN).push(id);
        MINE.with(|m| m.borrow_mut().push(id));
        ReadScope { id }
    }

    /// Stops recording (the files read so far stay protected until the scope is dropped): a
    /// long-lived job such as the studio keeps the files it opened, not what later requests
    /// read.
    pub fn freeze(&self) {
        lock(&OPEN).retain(|&s| s != self.id);
        MINE.with(|m| m.borrow_mut().retain(|&s| s != self.id));
    }

    /// The files this scope recorded, in the order read (each once).
    pub fn files(&self) -> Vec<PathBuf> {
        let read = lock(&READ);
        let mut out: Vec<PathBuf> = Vec::new();
        let mut keys: Vec<&FileKey> = Vec::new();
        for e in read.iter().filter(|e| e.scope == self.id) {
            if !keys.contains(&&e.key) {
                keys.push(&e.key);
                out.push(e.path.clone());
            }
        }
        out
    }
}

impl Drop for ReadScope {
    fn drop(&mut self) {
        self.freeze();
        lock(&READ).retain(|e| e.scope != self.id);
    }
}

/// A poisoned lock only means another thread panicked while holding it: the list is intact.
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}

/// Records that `path` was read, for the scopes this thread opened, or every open scope when
/// it opened none (nothing when none is open).
pub fn note_read(path: &Path) {
    let open = lock(&OPEN).clone();
    if open.is_empty() {
        return;
    }
    let mine: Vec<u64> = MINE.with(|m| {
        m.borrow()
            .iter()
            .copied()
            .filter(|s| open.contains(s))
            .collect()
    });
    let scopes = if mine.is_empty() { open } else { mine };
    let Some(key) = FileKey::of(path) else {
        return;
    };
    let mut read = lock(&READ);
    for scope in scopes {
        if !read.iter().any(|e| e.scope == scope && e.key == key) {
            read.push(Entry {
                scope,
                key: key.clone(),
                path: path.to_path_buf(),
            });
        }
    }
}

/// Refuses to write `target` when it is a file an open scope read (the same device and
/// inode: symlinks and other spellings of the path count).
///
/// # Errors
/// [`IoError::WouldOverwriteInput`] naming both paths.
pub fn check_not_input(target: &Path) -> Result<()> {
    let Some(key) = FileKey::of(target) else {
        return Ok(());
    };
    let read = lock(&READ);
    match read.iter().find(|e| e.key == key) {
        Some(e) => Err(IoError::WouldOverwriteInput {
            path: crate::FilePath(target.to_path_buf()),
            input: e.path.clone(),
        }),
        None => Ok(()),
    }
}

/// Whether two paths name the same existing file (device and inode).
pub fn same_file(a: &Path, b: &Path) -> bool {
    matches!((FileKey::of(a), FileKey::of(b)), (Some(x), Some(y)) if x == y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_symlink_and_an_alias_of_an_input_are_refused_and_others_are_not() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("fox.glb");
        std::fs::write(&input, b"glTF").unwrap();
        let link = dir.path().join("link.glb");
        #[cfg(unix)]
        std::os::unix::fs::symlink(&input, &link).unwrap();
        let scope = ReadScope::open();
        note_read(&link);
        let alias = dir.path().join("sub/../fox.glb");
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let e = check_not_input(&alias).unwrap_err().to_string();
        assert!(e.contains("fox.glb") && e.contains("link.glb"), "{e}");
        assert!(check_not_input(&dir.path().join("other.glb")).is_ok());
        assert_eq!(scope.files(), vec![link.clone()]);
        drop(scope);
        assert!(check_not_input(&input).is_ok(), "forgotten with the scope");
    }

    /// Two jobs on two threads: each scope records its own thread's reads only (a batch
    /// stamp hashes what its shot read), and both are protected from every write.
    #[test]
    fn scopes_on_two_threads_record_their_own_reads() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.obj"), dir.path().join("b.obj"));
        std::fs::write(&a, b"a").unwrap();
        std::fs::write(&b, b"b").unwrap();
        let barrier = std::sync::Barrier::new(2);
        let job = |p: &Path| {
            let scope = ReadScope::open();
            barrier.wait();
            note_read(p);
            barrier.wait();
            assert!(check_not_input(&a).is_err() && check_not_input(&b).is_err());
            barrier.wait();
            scope.files()
        };
        let (sa, sb) = std::thread::scope(|s| {
            let ha = s.spawn(|| job(&a));
            let hb = s.spawn(|| job(&b));
            (ha.join().unwrap(), hb.join().unwrap())
        });
        assert_eq!((sa, sb), (vec![a], vec![b]));
    }
}
