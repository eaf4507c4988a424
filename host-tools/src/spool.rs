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
//!
//! A stream cannot fill the disk: one whose first [`PROBE_LEN`] bytes hold
//! no valid log block (`/dev/zero`, `yes`, a serial line of text) is not a
//! log and is refused there, and none is copied beyond [`MAX_LEN`], the
//! largest file a card's FAT32 file system can hold. Standard input that
//! cannot be opened by name (a socket) is read from the descriptor.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, PoisonError};

use wobble_core::format::Decoder;

use crate::CliError;

/// Bytes of a stream read before it is refused for holding no valid block.
pub const PROBE_LEN: u64 = 16 << 20;

/// The longest stream copied: the largest file FAT32 holds.
pub const MAX_LEN: u64 = (4 << 30) - 1;

/// Bytes read from a stream at a time.
const CHUNK_LEN: usize = 1 << 20;

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
    // A stream already copied is read from its copy: opening a FIFO again
    // would wait for a writer that is gone.
    let mut spooled = SPOOLED.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some((_, copy)) = spooled.iter().find(|(p, _)| p == path) {
        let mut copy = copy.try_clone().map_err(io)?;
        let len = copy.seek(SeekFrom::End(0)).map_err(io)?;
        copy.seek(SeekFrom::Start(0)).map_err(io)?;
        return Ok((copy, len));
    }
    let source = match open(path).map_err(io)? {
        Source::File(mut file) => {
            let meta = file.metadata().map_err(io)?;
            if meta.is_file() || is_block_device(&meta) {
                // A card in a reader is seekable, with no length in its
                // metadata.
                let len = file.seek(SeekFrom::End(0)).map_err(io)?;
                file.seek(SeekFrom::Start(0)).map_err(io)?;
                return Ok((file, len));
            }
            Source::File(file)
        }
        Source::Stdin => Source::Stdin,
    };
    let (mut copy, len) = match source {
        Source::File(mut file) => copied(path, &mut file),
        Source::Stdin => copied(path, &mut std::io::stdin().lock()),
    }?;
    let failed = |e| copy_failed(path, e);
    copy.seek(SeekFrom::Start(0)).map_err(failed)?;
    spooled.push((path.to_path_buf(), copy.try_clone().map_err(failed)?));
    Ok((copy, len))
}

/// Copies the log stream `from` to a temporary file that every later
/// reading of `name` reads, as a stream given by its path is: for a stream
/// that has no path (a Python file object).
///
/// # Errors
/// As for a stream read through a path: no valid block in its first
/// [`PROBE_LEN`] bytes, longer than [`MAX_LEN`], or the copy fails.
pub fn adopt(name: &Path, from: &mut impl Read) -> Result<(), CliError> {
    let (copy, _) = copied(name, from)?;
    let mut spooled = SPOOLED.lock().unwrap_or_else(PoisonError::into_inner);
    spooled.retain(|(p, _)| p != name);
    spooled.push((name.to_path_buf(), copy));
    Ok(())
}

/// `from` copied to a new unnamed temporary file, and its length.
fn copied(path: &Path, from: &mut impl Read) -> Result<(File, u64), CliError> {
    let mut copy = tempfile::tempfile().map_err(|e| copy_failed(path, e))?;
    let len = copy_log(from, &mut copy).map_err(|e| match e {
        Copy::Io(e) => copy_failed(path, e),
        Copy::Refused(message) => CliError::file(path, message),
    })?;
    Ok((copy, len))
}

/// The error of a copy of the stream `path` that failed with `e`.
fn copy_failed(path: &Path, e: std::io::Error) -> CliError {
    CliError::file(
        path,
        format!(
            "copying the stream to a temporary file in {} (to decode its blocks in order): {e}",
            crate::text::shown(std::env::temp_dir())
        ),
    )
}

/// Where a stream is read from.
enum Source {
    File(File),
    /// Standard input, read from its descriptor: a socket has no name to
    /// open it by.
    Stdin,
}

/// Opens `path`, or standard input's descriptor for a name of it that the
/// system cannot open (`/dev/stdin` on a socket: "no such device").
fn open(path: &Path) -> std::io::Result<Source> {
    match File::open(path) {
        Ok(file) => Ok(Source::File(file)),
        Err(e)
            if e.raw_os_error() == Some(ENXIO)
                && crate::output::open_descriptor(path) == Some(0) =>
        {
            Ok(Source::Stdin)
        }
        Err(e) => Err(e),
    }
}

/// "No such device or address": what opening a socket by name gives.
const ENXIO: i32 = 6;

enum Copy {
    Io(std::io::Error),
    Refused(String),
}

/// Copies the stream `from` into `to`, returning its length; refused when
/// its first [`PROBE_LEN`] bytes hold no valid block or it passes
/// [`MAX_LEN`].
fn copy_log(from: &mut impl Read, to: &mut File) -> Result<u64, Copy> {
    let mut probe = Decoder::new();
    let mut found = false;
    let mut buf = vec![0u8; CHUNK_LEN];
    let mut filled = 0;
    let mut len = 0u64;
    loop {
        let n = match from.read(&mut buf[filled..]) {
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(Copy::Io(e)),
        };
        to.write_all(&buf[filled..filled + n]).map_err(Copy::Io)?;
        len += n as u64;
        filled += n;
        if len > MAX_LEN {
            return Err(Copy::Refused(format!(
                "the stream is longer than any card log can be ({} bytes, the FAT32 file size \
                 limit); stopped copying it",
                MAX_LEN
            )));
        }
        let at_end = n == 0;
        if !found {
            let consumed = probe.scan(&buf[..filled], at_end, &mut |_| {}, &mut |_, _| {
                found = true;
            });
            buf.copy_within(consumed..filled, 0);
            filled -= consumed;
            if !found && len >= PROBE_LEN {
                return Err(Copy::Refused(format!(
                    "no valid log block in the stream's first {} MiB: not a wobble-logger log \
                     (stopped reading it)",
                    PROBE_LEN >> 20
                )));
            }
        } else {
            filled = 0;
        }
        if at_end {
            return Ok(len);
        }
    }
}

#[cfg(unix)]
fn is_block_device(meta: &std::fs::Metadata) -> bool {
    std::os::unix::fs::FileTypeExt::is_block_device(&meta.file_type())
}

#[cfg(not(unix))]
fn is_block_device(_: &std::fs::Metadata) -> bool {
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A FIFO at a new path in `dir`, fed `bytes` once by a writer thread.
    fn fifo_with(dir: &Path, bytes: Vec<u8>) -> PathBuf {
        let fifo = dir.join("f.fifo");
        assert!(std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success());
        let path = fifo.clone();
        std::thread::spawn(move || std::fs::write(path, bytes));
        fifo
    }

    fn read_all(mut file: File) -> Vec<u8> {
        let mut bytes = Vec::new();
        file.read_to_end(&mut bytes).unwrap();
        bytes
    }

    #[test]
    fn a_stream_opened_twice_reads_whole_from_its_start_both_times() {
        let dir = tempfile::tempdir().unwrap();
        // A block of any content is copied: the probe looks for a valid
        // block only after PROBE_LEN bytes.
        let bytes: Vec<u8> = (0..3000u32).map(|i| (i % 251) as u8).collect();
        let fifo = fifo_with(dir.path(), bytes.clone());
        let (first, len) = open_seekable(&fifo).unwrap();
        assert_eq!(len, bytes.len() as u64);
        assert_eq!(read_all(first), bytes);
        // The second open (the FIFO's writer is gone) is the same copy,
        // rewound after the first reader left it at its end.
        let (second, len) = open_seekable(&fifo).unwrap();
        assert_eq!(len, bytes.len() as u64);
        assert_eq!(read_all(second), bytes);
    }

    #[test]
    fn an_adopted_stream_is_read_under_its_name_and_a_second_one_replaces_it() {
        let name = Path::new("<stream adopted>");
        let bytes: Vec<u8> = (0..5000u32).map(|i| (i % 241) as u8).collect();
        adopt(name, &mut bytes.as_slice()).unwrap();
        for _ in 0..2 {
            let (copy, len) = open_seekable(name).unwrap();
            assert_eq!(len, bytes.len() as u64);
            assert_eq!(read_all(copy), bytes);
        }
        adopt(name, &mut &b"other"[..]).unwrap();
        assert_eq!(read_all(open_seekable(name).unwrap().0), b"other");
        // Past PROBE_LEN without a block: refused, named, nothing adopted.
        let zeros = std::io::repeat(0).take(PROBE_LEN + 1);
        let refused = Path::new("<stream of zeros>");
        let err = adopt(refused, &mut zeros.take(PROBE_LEN + 1)).unwrap_err();
        assert!(
            err.to_string()
                .starts_with("<stream of zeros>: no valid log block"),
            "{err}"
        );
        assert!(open_seekable(refused).is_err());
    }
}
