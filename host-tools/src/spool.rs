//! A log read from a stream (a pipe, standard input, a socket) is copied to
//! a temporary file first, so it is decoded like a file: every unique
//! valid block once, in sequence order, whatever order the stream carries
//! them in (a stream cannot be read twice, and a reorder buffer of any
//! fixed size misses a block that arrives further out of place).
//!
//! The copy is an unnamed file in the temporary directory (`TMPDIR`, else
//! `/tmp`), as large as the stream; it has no name, so nothing is left
//! behind whatever ends the process. Memory use does not grow with it.
//! A command that reads its log twice (`decode` looks for the first UTC
//! sync pair before it writes rows) reads the same copy both times.

use std::fs::File;
use std::io::{Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, PoisonError};

use crate::CliError;

/// The streams copied so far by this process, by the path they were read
/// through.
static SPOOLED: Mutex<Vec<(PathBuf, File)>> = Mutex::new(Vec::new());

/// Opens the log at `path` at its start for reading, with its length: a
/// file or block device as it is, anything else through its temporary copy.
///
/// # Errors
/// The log cannot be opened or read, or the copy cannot be written (the
/// message says where, and why).
pub fn open_seekable(path: &Path) -> Result<(File, u64), CliError> {
    let io = |e| CliError::file(path, e);
    let mut file = File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if meta.is_file() {
        return Ok((file, meta.len()));
    }
    if is_block_device(&meta) {
        // A card in a reader: seekable, with no length in its metadata.
        let len = file.seek(SeekFrom::End(0)).map_err(io)?;
        file.seek(SeekFrom::Start(0)).map_err(io)?;
        return Ok((file, len));
    }
    let mut spooled = SPOOLED.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some((_, copy)) = spooled.iter().find(|(p, _)| p == path) {
        let mut copy = copy.try_clone().map_err(io)?;
        let len = copy.seek(SeekFrom::End(0)).map_err(io)?;
        copy.seek(SeekFrom::Start(0)).map_err(io)?;
        return Ok((copy, len));
    }
    let failed = |e: std::io::Error| {
        CliError::file(
            path,
            format!(
                "copying the stream to a temporary file in {} (to decode its blocks in order): {e}",
                crate::text::shown(std::env::temp_dir())
            ),
        )
    };
    let mut copy = tempfile::tempfile().map_err(failed)?;
    let len = std::io::copy(&mut file, &mut copy).map_err(failed)?;
    copy.seek(SeekFrom::Start(0)).map_err(failed)?;
    spooled.push((path.to_path_buf(), copy.try_clone().map_err(failed)?));
    Ok((copy, len))
}

#[cfg(unix)]
fn is_block_device(meta: &std::fs::Metadata) -> bool {
    std::os::unix::fs::FileTypeExt::is_block_device(&meta.file_type())
}

#[cfg(not(unix))]
fn is_block_device(_: &std::fs::Metadata) -> bool {
    false
}
