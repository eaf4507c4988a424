//! A command's inputs told apart by what they are, not by their names: a
//! file is its device and inode number, so a log named twice, reached
//! through a folder and by its own path, through a symlink or a hard link
//! is one input, and a byte-identical copy of a log is one log's data.
//!
//! Files are compared by their metadata (`stat`), never by opening them:
//! opening a FIFO to compare it takes its writer's only reader.

use std::collections::HashMap;
use std::fs::{self, File};
use std::hash::Hasher;
use std::io::{self, Read};
use std::path::{Path, PathBuf};

/// Bytes read at a time while comparing contents.
const READ_LEN: usize = 1 << 16;

/// A file's device and inode number: the same for every name of one file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Identity {
    dev: u64,
    ino: u64,
}

impl Identity {
    /// The identity of the file `path` names (links followed), or `None`
    /// when it does not exist or cannot be looked at (it then cannot be
    /// the same file as anything this process writes).
    #[must_use]
    pub fn of(path: &Path) -> Option<Self> {
        fs::metadata(path).ok().map(|m| Self::from_metadata(&m))
    }

    /// The identity in `meta`.
    #[cfg(unix)]
    #[must_use]
    pub fn from_metadata(meta: &fs::Metadata) -> Self {
        use std::os::unix::fs::MetadataExt;
        Self {
            dev: meta.dev(),
            ino: meta.ino(),
        }
    }

    /// Without device and inode numbers, every file is its own.
    #[cfg(not(unix))]
    #[must_use]
    pub fn from_metadata(_: &fs::Metadata) -> Self {
        use std::sync::atomic::{AtomicU64, Ordering};
        static NEXT: AtomicU64 = AtomicU64::new(0);
        Self {
            dev: 0,
            ino: NEXT.fetch_add(1, Ordering::Relaxed),
        }
    }
}

/// `paths` with every file after its first appearance left out, in order:
/// a second name of one file (same device and inode), or a regular file
/// whose bytes are those of an earlier one (a copy). Each one left out is
/// named on stderr with the input it repeats, as the analysis counts it
/// once. A path that cannot be looked at is kept, for its reader to report.
#[must_use]
pub fn distinct(paths: Vec<PathBuf>) -> Vec<PathBuf> {
    let mut kept: Vec<PathBuf> = Vec::with_capacity(paths.len());
    let mut by_identity: HashMap<Identity, usize> = HashMap::new();
    // Regular files kept so far, by length, then by content hash.
    let mut by_len: HashMap<u64, Vec<usize>> = HashMap::new();
    let mut hashes: HashMap<usize, u64> = HashMap::new();
    for path in paths {
        let Ok(meta) = fs::metadata(&path) else {
            kept.push(path);
            continue;
        };
        let identity = Identity::from_metadata(&meta);
        if let Some(&first) = by_identity.get(&identity) {
            note(&path, &kept[first], "the same file as");
            continue;
        }
        if meta.is_file() {
            let twins = by_len.get(&meta.len()).cloned().unwrap_or_default();
            if let Some(first) = copy_of(&path, &twins, &kept, &mut hashes) {
                note(&path, &kept[first], "a copy of");
                continue;
            }
            by_len.entry(meta.len()).or_default().push(kept.len());
        }
        by_identity.insert(identity, kept.len());
        kept.push(path);
    }
    kept
}

fn note(path: &Path, first: &Path, what: &str) {
    eprintln!(
        "wobblog: note: {} is {what} {}; counted once",
        crate::text::shown(path),
        crate::text::shown(first)
    );
}

/// The index in `kept` of the file among `twins` (kept files of `path`'s
/// length) whose bytes are `path`'s: hashes first (each file read once
/// for it), then the bytes themselves for a matching hash.
fn copy_of(
    path: &Path,
    twins: &[usize],
    kept: &[PathBuf],
    hashes: &mut HashMap<usize, u64>,
) -> Option<usize> {
    if twins.is_empty() {
        return None;
    }
    let hash = content_hash(path).ok()?;
    for &i in twins {
        let theirs = match hashes.get(&i) {
            Some(&h) => h,
            None => {
                let Ok(h) = content_hash(&kept[i]) else {
                    continue;
                };
                hashes.insert(i, h);
                h
            }
        };
        if theirs == hash && same_bytes(path, &kept[i]).unwrap_or(false) {
            return Some(i);
        }
    }
    None
}

/// A hash of the file's bytes (the standard library's SipHash: a match is
/// confirmed byte by byte, so it need not resist collisions).
fn content_hash(path: &Path) -> io::Result<u64> {
    let mut file = File::open(path)?;
    let mut hasher = std::hash::DefaultHasher::new();
    let mut buf = vec![0u8; READ_LEN];
    loop {
        let n = file.read(&mut buf)?;
        if n == 0 {
            return Ok(hasher.finish());
        }
        hasher.write(&buf[..n]);
    }
}

fn same_bytes(a: &Path, b: &Path) -> io::Result<bool> {
    let (mut a, mut b) = (File::open(a)?, File::open(b)?);
    let (mut x, mut y) = (vec![0u8; READ_LEN], vec![0u8; READ_LEN]);
    loop {
        let n = read_full(&mut a, &mut x)?;
        let m = read_full(&mut b, &mut y)?;
        if x[..n] != y[..m] {
            return Ok(false);
        }
        if n == 0 {
            return Ok(true);
        }
    }
}

/// Reads until `buf` is full or the file ends.
fn read_full(file: &mut File, buf: &mut [u8]) -> io::Result<usize> {
    let mut filled = 0;
    while filled < buf.len() {
        match file.read(&mut buf[filled..])? {
            0 => break,
            n => filled += n,
        }
    }
    Ok(filled)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_links_and_copies_of_one_file_are_kept_once() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("RUN00001.WBL");
        let b = dir.path().join("RUN00002.WBL");
        let copy = dir.path().join("RUN00003.WBL");
        let other = dir.path().join("RUN00004.WBL");
        fs::write(&a, b"the same bytes").unwrap();
        fs::hard_link(&a, &b).unwrap();
        fs::write(&copy, b"the same bytes").unwrap();
        // Same length, other bytes: kept.
        fs::write(&other, b"the same bytez").unwrap();
        let through_dot = dir.path().join(".").join("RUN00001.WBL");
        let kept = distinct(vec![
            a.clone(),
            through_dot,
            b,
            copy,
            other.clone(),
            a.clone(),
        ]);
        assert_eq!(kept, vec![a, other]);
    }

    #[test]
    fn a_missing_file_is_kept_for_its_reader_to_report() {
        let dir = tempfile::tempdir().unwrap();
        let gone = dir.path().join("gone.WBL");
        assert_eq!(distinct(vec![gone.clone()]), vec![gone]);
    }
}
