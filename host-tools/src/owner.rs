//! Temporary outputs owned by an advisory lock (`flock` on Unix): a writer holds
//! an exclusive lock on its temporary file (or `export`'s temporary
//! directory) from the moment it exists until it is renamed or removed, and
//! a later run removes a leftover only if it can take that lock itself. A
//! process ID in a name says nothing about a writer in another PID
//! namespace (a container sharing the volume, another NFS client); a lock
//! held by a live process is seen wherever the file is.

use std::fs::File;
use std::io;
use std::path::Path;

/// Takes the exclusive lock of `file` without waiting: `Ok(true)` when
/// taken (held as long as this open file is), `Ok(false)` when another
/// open file holds it.
///
/// # Errors
/// The file system does not lock files.
pub fn hold(file: &File) -> io::Result<bool> {
    match file.try_lock() {
        Ok(()) => Ok(true),
        Err(std::fs::TryLockError::WouldBlock) => Ok(false),
        Err(std::fs::TryLockError::Error(e)) => Err(e),
    }
}

/// Whether the temporary file or directory at `path` is left by a writer
/// that is gone: nobody holds its lock. `None` when that cannot be told
/// (it cannot be opened, or the file system does not lock).
#[must_use]
pub fn abandoned(path: &Path) -> Option<bool> {
    let file = File::open(path).ok()?;
    hold(&file).ok()
}

/// Attempts at making a temporary file that another run does not remove
/// before its lock is taken.
const ATTEMPTS: usize = 8;

/// Makes a temporary file or directory with `make` and takes its lock
/// through the open file `open` gives for it (kept open by the caller as
/// long as the lock must hold). One that another run found unlocked and
/// removed in the moment before the lock was taken is made again.
///
/// # Errors
/// Those of `make` and `open`, or the lock cannot be kept.
pub fn make_held<T>(
    mut make: impl FnMut() -> io::Result<T>,
    open: impl Fn(&T) -> io::Result<File>,
) -> io::Result<(T, File)> {
    for _ in 0..ATTEMPTS {
        let made = make()?;
        let file = open(&made)?;
        // A file system that does not lock keeps the old behaviour: the
        // file is written unowned.
        let held = hold(&file).unwrap_or(true);
        if held && still_linked(&file)? {
            return Ok((made, file));
        }
    }
    Err(io::Error::other(
        "another run kept removing the temporary file",
    ))
}

#[cfg(unix)]
fn still_linked(file: &File) -> io::Result<bool> {
    use std::os::unix::fs::MetadataExt;
    Ok(file.metadata()?.nlink() > 0)
}

#[cfg(not(unix))]
fn still_linked(_: &File) -> io::Result<bool> {
    Ok(true)
}

/// Removes the temporary file or directory at `path` if its writer is
/// gone (nobody holds its lock), with a note; where that cannot be told,
/// only notes it.
pub fn clear_abandoned(path: &Path) {
    let shown = crate::text::shown(path);
    match abandoned(path) {
        Some(true) => {
            let removed = if path.is_dir() {
                std::fs::remove_dir_all(path)
            } else {
                std::fs::remove_file(path)
            };
            if removed.is_ok() {
                eprintln!("wobblog: note: removed {shown}, left by an interrupted run");
            }
        }
        Some(false) => {}
        None => eprintln!("wobblog: note: {shown} may be left by an interrupted run"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_held_lock_is_seen_by_another_open_file_and_freed_with_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(".x.tmp");
        let writer = File::create(&path).unwrap();
        assert!(hold(&writer).unwrap());
        assert_eq!(abandoned(&path), Some(false));
        drop(writer);
        assert_eq!(abandoned(&path), Some(true));
        // A directory is locked the same way.
        let held = File::open(dir.path()).unwrap();
        assert!(hold(&held).unwrap());
        assert_eq!(abandoned(dir.path()), Some(false));
    }
}
