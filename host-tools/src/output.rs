//! Where every command writes: a file that appears whole or not at all, or
//! standard output.
//!
//! A file output is written to a temporary file beside its target (same
//! directory, so the final rename stays on one file system) and renamed
//! over the target only by [`Output::commit`]. Dropping an [`Output`]
//! without committing it, on any error path, removes the temporary file
//! and leaves whatever was at the target as it was. An output that is the
//! same file as one of the command's inputs (same path, a hard link, or a
//! symlink to it: device and inode numbers are compared, not names, and
//! no file is opened to compare it) is refused before anything is
//! created, and so is standard output when it is an input (`info LOG >>
//! LOG`, which `cat` refuses too): every command's standard output and
//! files are made here, so the rule holds for all of them.
//!
//! What is replaced, and how:
//! - a name for one of the process's open files (`/dev/stdout`,
//!   `/dev/stderr`, `/dev/fd/N`, `/proc/self/fd/N`, or a link to one) is
//!   written in place, appending: `-o /dev/stdout >> all.csv` appends like
//!   the redirection says; one open for reading only (`-o /dev/stdin`) is
//!   refused;
//! - a device, FIFO or socket is written in place;
//! - a symlink is followed to its destination (which may not exist yet),
//!   and the destination is replaced: the link stays a link;
//! - a replaced file keeps its permission bits;
//! - a write-protected file (no write bit) or one with other hard links
//!   (which a rename would split from it) is refused unless `--force`;
//! - a directory is refused before any work is done.
//!
//! The temporary file is `.NAME.PID.XXXXXX.tmp`, locked by its writer
//! ([`crate::owner`]); one left by a run that was killed (nobody holds its
//! lock) is removed, with a note, by the next run writing the same target,
//! and one whose writer lives, in whatever PID namespace, is left alone. Messages name the target, never the
//! temporary file.
//!
//! ```no_run
//! # use std::io::Write;
//! # use std::path::Path;
//! # fn main() -> Result<(), wobblog::CliError> {
//! use wobblog::output::Output;
//! let input = Path::new("RUN00001.WBL");
//! let mut out = Output::create(Path::new("run1.csv"), &[input])?;
//! writeln!(out, "t_s").map_err(|e| out.error(e))?;
//! out.commit()?; // only now does run1.csv appear (or change)
//! # Ok(())
//! # }
//! ```

use std::fs::{self, OpenOptions};
use std::io::{self, BufWriter, Stdout, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use tempfile::NamedTempFile;

use crate::inputs::Identity;
use crate::CliError;

/// Bytes buffered before they go to the file or pipe.
const BUFFER_LEN: usize = 1 << 16;

/// Longest file name most file systems take, bytes.
const NAME_MAX: usize = 255;

/// Symlinks followed before a target is refused as a loop (as the kernel's
/// own limit).
const MAX_LINKS: usize = 40;

/// `--force`: replace write-protected files and files with other hard links.
static FORCE: AtomicBool = AtomicBool::new(false);

/// Sets whether outputs replace write-protected and hard-linked files.
pub fn set_force(force: bool) {
    FORCE.store(force, Ordering::Relaxed);
}

/// One command output: an atomically replaced file, or standard output.
pub struct Output {
    sink: Sink,
    /// The target as given, for messages.
    name: PathBuf,
    /// A write found standard output closed. Writers such as Parquet's
    /// wrap the I/O error in their own, hiding its kind from the caller.
    pipe_closed: bool,
}

enum Sink {
    File {
        temp: BufWriter<Temp>,
        /// Where the temporary file goes on commit (a symlinked target's
        /// destination, so the link stays a link).
        target: PathBuf,
    },
    Stdout(BufWriter<Stdout>),
    /// A device or FIFO named as the output, written in place.
    Device(BufWriter<std::fs::File>),
}

impl Output {
    /// An output to the file at `target`, refused if it is the same file as
    /// any of `inputs`. Nothing at `target` changes until [`Self::commit`].
    pub fn create(target: &Path, inputs: &[&Path]) -> Result<Self, CliError> {
        refuse_inputs(target, inputs)?;
        // One of this process's open files: written through, appending, so
        // a redirection's `>>` stays an append and nothing is renamed over
        // the file behind it. One it only reads (`-o /dev/stdin`) is an
        // input, never an output.
        if let Some(fd) = open_descriptor(target) {
            if opened_read_only(fd) {
                return Err(CliError::Usage(format!(
                    "{}: descriptor {fd} is open for reading only (an input); \
                     refusing to write into it",
                    crate::text::shown(target)
                )));
            }
            return Self::in_place(target, target, OpenOptions::new().append(true));
        }
        let resolved = follow_links(target).map_err(|e| CliError::file(target, plain(&e)))?;
        let existing = match fs::metadata(&resolved) {
            Ok(meta) => Some(meta),
            Err(e) if e.kind() == io::ErrorKind::NotFound => None,
            Err(e) => return Err(CliError::file(target, plain(&e))),
        };
        if existing.as_ref().is_some_and(fs::Metadata::is_dir) || ends_with_slash(target) {
            return Err(CliError::Usage(format!(
                "{}: is a directory; name a file to write",
                crate::text::shown(target)
            )));
        }
        // A device or a pipe (`-o /dev/null`, a FIFO) is written as it is:
        // renaming a file over it would replace the device itself.
        if existing.as_ref().is_some_and(|m| !m.is_file()) {
            return Self::in_place(target, &resolved, OpenOptions::new().write(true));
        }
        if let Some(meta) = &existing {
            refuse_protected(target, meta)?;
        }
        remove_stale(&resolved);
        let temp = temp_beside(&resolved, existing.as_ref()).map_err(|e| {
            CliError::file(target, format!("cannot create the output: {}", plain(&e)))
        })?;
        Ok(Self {
            sink: Sink::File {
                temp: BufWriter::with_capacity(BUFFER_LEN, Temp::new(temp)),
                target: resolved,
            },
            name: target.to_path_buf(),
            pipe_closed: false,
        })
    }

    /// The output's two exceptions to the temporary file and rename: the
    /// file at `path` (`target` or where its links lead), opened with
    /// `options` and written where it is.
    fn in_place(target: &Path, path: &Path, options: &OpenOptions) -> Result<Self, CliError> {
        let file = options
            .open(path)
            .map_err(|e| CliError::file(target, plain(&e)))?;
        Ok(Self {
            sink: Sink::Device(BufWriter::with_capacity(BUFFER_LEN, file)),
            name: target.to_path_buf(),
            pipe_closed: false,
        })
    }

    /// An output to standard output, refused when standard output is one
    /// of `inputs` (`info LOG >> LOG`, `summary CARD 1<> CARD/RUN00001.WBL`).
    /// A reader that goes away (`| head`) ends the command quietly: see
    /// [`Self::error`].
    ///
    /// # Errors
    /// Standard output is one of `inputs` (a usage error).
    pub fn stdout(inputs: &[&Path]) -> Result<Self, CliError> {
        refuse_stdout_input(inputs)?;
        Ok(Self {
            sink: Sink::Stdout(BufWriter::with_capacity(BUFFER_LEN, io::stdout())),
            name: PathBuf::from("<stdout>"),
            pipe_closed: false,
        })
    }

    /// [`Self::create`] for `Some(target)`, else [`Self::stdout`].
    ///
    /// # Errors
    /// Those of either.
    pub fn create_or_stdout(target: Option<&Path>, inputs: &[&Path]) -> Result<Self, CliError> {
        match target {
            Some(t) => Self::create(t, inputs),
            None => Self::stdout(inputs),
        }
    }

    /// The output's name in messages: the target path, or `<stdout>`.
    #[must_use]
    pub fn name(&self) -> &Path {
        &self.name
    }

    /// Whether this output is standard output.
    #[must_use]
    pub fn is_stdout(&self) -> bool {
        matches!(self.sink, Sink::Stdout(_))
    }

    /// The error to end the command with after writing failed with `err`:
    /// the output's name and the system's reason, or, for a closed pipe on
    /// standard output, [`CliError::PipeClosed`] (a quiet, successful end).
    #[must_use]
    pub fn error(&self, err: impl Into<Box<dyn std::error::Error>>) -> CliError {
        let err: Box<dyn std::error::Error> = err.into();
        let broken = err
            .downcast_ref::<io::Error>()
            .is_some_and(|e| e.kind() == io::ErrorKind::BrokenPipe);
        if self.pipe_closed || (self.is_stdout() && broken) {
            CliError::PipeClosed
        } else {
            CliError::file(&self.name, err)
        }
    }

    /// Whether a write found standard output closed by its reader.
    #[must_use]
    pub fn pipe_closed(&self) -> bool {
        self.pipe_closed
    }

    fn note(&mut self, result: io::Result<()>) -> io::Result<()> {
        if let Err(e) = &result {
            self.pipe_closed |= self.is_stdout() && e.kind() == io::ErrorKind::BrokenPipe;
        }
        result
    }

    /// Makes the output final: flushes it, and for a file syncs it to disk
    /// and renames it over the target.
    pub fn commit(self) -> Result<(), CliError> {
        let name = self.name;
        match self.sink {
            Sink::Device(mut out) => out.flush().map_err(|e| CliError::file(&name, e)),
            Sink::Stdout(mut out) => out.flush().map_err(|e| {
                if e.kind() == io::ErrorKind::BrokenPipe {
                    CliError::PipeClosed
                } else {
                    CliError::file(&name, e)
                }
            }),
            Sink::File { temp, target } => {
                let mut temp = temp
                    .into_inner()
                    .map_err(|e| CliError::file(&name, plain(&e.into_error())))?;
                let file = temp
                    .file
                    .take()
                    .ok_or_else(|| CliError::file(&name, "committed twice"))?;
                file.as_file()
                    .sync_all()
                    .map_err(|e| CliError::file(&name, plain(&e)))?;
                // `temp` is dropped (untracked) only after the rename.
                file.persist(&target).map(drop).map_err(|e| {
                    CliError::file(&name, format!("cannot replace: {}", plain(&e.error)))
                })
            }
        }
    }
}

impl Write for Output {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let mut written = 0;
        let result = match &mut self.sink {
            Sink::File { temp, .. } => temp.write(buf),
            Sink::Device(out) => out.write(buf),
            Sink::Stdout(out) => out.write(buf),
        }
        .map(|n| written = n);
        self.note(result).map(|()| written)
    }

    fn flush(&mut self) -> io::Result<()> {
        let result = match &mut self.sink {
            Sink::File { temp, .. } => temp.flush(),
            Sink::Device(out) => out.flush(),
            Sink::Stdout(out) => out.flush(),
        };
        self.note(result)
    }
}

/// A temporary output file, removed if a signal ends the process before it
/// is committed or dropped ([`crate::interrupt`]).
struct Temp {
    /// `None` once taken to be committed.
    file: Option<NamedTempFile>,
    path: PathBuf,
}

impl Temp {
    /// Takes a temporary file made by [`crate::interrupt::make_tracked`].
    fn new(file: NamedTempFile) -> Self {
        let path = file.path().to_path_buf();
        Self {
            file: Some(file),
            path,
        }
    }

    fn file(&mut self) -> io::Result<&mut NamedTempFile> {
        self.file
            .as_mut()
            .ok_or_else(|| io::Error::other("the output was committed"))
    }
}

impl Write for Temp {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.file()?.write(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.file()?.flush()
    }
}

impl Drop for Temp {
    fn drop(&mut self) {
        // Removes the file unless it was committed, then stops tracking it.
        drop(self.file.take());
        crate::interrupt::untrack(&self.path);
    }
}

/// Refuses `target` if it is the same file as one of `inputs`: the same
/// device and inode, whatever the names (a hard link, a symlink,
/// `/dev/stdout` or `/dev/fd/N` of a redirected input). A target or input
/// that does not exist (yet) cannot be the same file.
fn refuse_inputs(target: &Path, inputs: &[&Path]) -> Result<(), CliError> {
    let Some(output) = Identity::of(target) else {
        return Ok(());
    };
    match inputs.iter().find(|i| Identity::of(i) == Some(output)) {
        Some(input) => Err(CliError::Usage(format!(
            "{}: the output is the input {}; refusing to overwrite it",
            crate::text::shown(target),
            crate::text::shown(input)
        ))),
        None => Ok(()),
    }
}

/// Refuses an input that is standard output, by device and inode, when
/// standard output is a file that can be written anywhere in it (a regular
/// file or a block device). A terminal or pipe that is also read is left
/// to the user, as `cat` does.
fn refuse_stdout_input(inputs: &[&Path]) -> Result<(), CliError> {
    let Ok(stdout) = same_file::Handle::stdout() else {
        return Ok(());
    };
    let Ok(meta) = stdout.as_file().metadata() else {
        return Ok(());
    };
    if !(meta.is_file() || is_block_device(&meta)) {
        return Ok(());
    }
    let output = Identity::from_metadata(&meta);
    match inputs.iter().find(|i| Identity::of(i) == Some(output)) {
        Some(input) => Err(CliError::Usage(format!(
            "{}: standard output is the input; refusing to write into it",
            crate::text::shown(input)
        ))),
        None => Ok(()),
    }
}

#[cfg(unix)]
fn is_block_device(meta: &fs::Metadata) -> bool {
    std::os::unix::fs::FileTypeExt::is_block_device(&meta.file_type())
}

#[cfg(not(unix))]
fn is_block_device(_: &fs::Metadata) -> bool {
    false
}

/// The descriptor number when `path`, or a link on the way from it, names
/// one of this process's open files (`/dev/stdout`, `/dev/fd/3`,
/// `/proc/self/fd/1`).
pub(crate) fn open_descriptor(path: &Path) -> Option<u32> {
    let mut path = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        if let Some(fd) = descriptor_named(&path) {
            return Some(fd);
        }
        path = beside(&path, fs::read_link(&path).ok()?);
    }
    None
}

fn descriptor_named(path: &Path) -> Option<u32> {
    let parts: Vec<String> = path
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    let parts: Vec<&str> = parts.iter().map(String::as_str).collect();
    let own =
        |pid: &str| pid == "self" || pid == "thread-self" || pid == std::process::id().to_string();
    let number = match parts.as_slice() {
        ["/", "dev", "stdin"] => "0",
        ["/", "dev", "stdout"] => "1",
        ["/", "dev", "stderr"] => "2",
        ["/", "dev", "fd", n] => n,
        ["/", "proc", pid, "fd", n] if own(pid) => n,
        ["/", "proc", pid, "task", _, "fd", n] if own(pid) => n,
        _ => return None,
    };
    number.parse().ok()
}

/// Whether this process opened descriptor `fd` for reading only (the
/// access mode in `/proc/self/fdinfo`; where that cannot be read, standard
/// input is taken as read-only and the rest as writable).
fn opened_read_only(fd: u32) -> bool {
    /// `O_ACCMODE` and `O_RDONLY` of Linux's open flags.
    const ACCESS_MODE: u32 = 0o3;
    const READ_ONLY: u32 = 0;
    let flags = fs::read_to_string(format!("/proc/self/fdinfo/{fd}"))
        .ok()
        .and_then(|info| {
            info.lines()
                .find_map(|l| l.strip_prefix("flags:"))
                .and_then(|f| u32::from_str_radix(f.trim(), 8).ok())
        });
    match flags {
        Some(flags) => flags & ACCESS_MODE == READ_ONLY,
        None => fd == 0,
    }
}

/// Where a link at `link` whose content is `next` points.
fn beside(link: &Path, next: PathBuf) -> PathBuf {
    if next.is_absolute() {
        next
    } else {
        link.parent().unwrap_or(Path::new("")).join(next)
    }
}

/// The path at the end of `target`'s chain of symlinks (which may not
/// exist: a dangling link's file is created where it points).
fn follow_links(target: &Path) -> io::Result<PathBuf> {
    let mut path = target.to_path_buf();
    for _ in 0..MAX_LINKS {
        match fs::symlink_metadata(&path) {
            Ok(m) if m.file_type().is_symlink() => path = beside(&path, fs::read_link(&path)?),
            _ => return Ok(path),
        }
    }
    Err(io::Error::other("too many levels of symbolic links"))
}

fn ends_with_slash(path: &Path) -> bool {
    path.as_os_str().to_string_lossy().ends_with('/')
}

/// Refuses to replace a write-protected file, or one with other hard links
/// (the new file would have this name only), unless `--force`.
fn refuse_protected(target: &Path, meta: &fs::Metadata) -> Result<(), CliError> {
    if FORCE.load(Ordering::Relaxed) {
        return Ok(());
    }
    let shown = crate::text::shown(target);
    if meta.permissions().readonly() {
        return Err(CliError::Usage(format!(
            "{shown}: the file is write-protected; --force replaces it"
        )));
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if meta.nlink() > 1 {
            return Err(CliError::Usage(format!(
                "{shown}: the file has {} other hard links, which replacing it would split \
                 from it; --force replaces this name only",
                meta.nlink() - 1
            )));
        }
    }
    Ok(())
}

/// An I/O error's reason without any path in it (the temporary file's
/// name means nothing to the user; `tempfile` appends it as " at path").
fn plain(e: &io::Error) -> String {
    if let Some(code) = e.raw_os_error() {
        return io::Error::from_raw_os_error(code).to_string();
    }
    let text = e.to_string();
    match text.find(" at path ") {
        Some(end) => text[..end].to_string(),
        None => text,
    }
}

/// The name part of a temporary file for `target`: its file name, cut at
/// a character boundary so the whole temporary name fits `NAME_MAX`.
fn temp_stem(target: &Path) -> String {
    let name = target.file_name().unwrap_or_default().to_string_lossy();
    // ".", ".", pid (at most 10 digits), ".", 6 random, ".tmp"
    let room = NAME_MAX - (1 + 1 + 10 + 1 + 6 + 4);
    let mut end = name.len().min(room);
    while !name.is_char_boundary(end) {
        end -= 1;
    }
    name[..end].to_string()
}

fn dir_of(target: &Path) -> &Path {
    match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Removes temporary files of `target` left by runs that are gone (killed
/// before they could clean up: nobody holds their lock), with a note for
/// each.
fn remove_stale(target: &Path) {
    let dir = dir_of(target);
    let prefix = format!(".{}.", temp_stem(target));
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let name = name.to_string_lossy();
        let Some(rest) = name
            .strip_prefix(&prefix)
            .and_then(|r| r.strip_suffix(".tmp"))
        else {
            continue;
        };
        let Some((pid, random)) = rest.split_once('.') else {
            continue;
        };
        if random.len() != 6 || pid.is_empty() || !pid.bytes().all(|b| b.is_ascii_digit()) {
            continue;
        }
        crate::owner::clear_abandoned(&entry.path());
    }
}

/// A new temporary file beside `target`, with a hidden name that says what
/// it will become and which process writes it, with the permission bits
/// of the file it replaces (`existing`), or readable by others as a file
/// the user creates would be (the umask still applies).
fn temp_beside(target: &Path, existing: Option<&fs::Metadata>) -> io::Result<NamedTempFile> {
    let prefix = format!(".{}.{}.", temp_stem(target), std::process::id());
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp").rand_bytes(6);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(fs::Permissions::from_mode(0o666));
    }
    // Locked from the start: another run never takes it for a leftover.
    let (temp, _) = crate::interrupt::make_tracked(
        || {
            crate::owner::make_held(
                || builder.tempfile_in(dir_of(target)),
                |t| t.as_file().try_clone(),
            )
        },
        |(t, _)| t.path(),
    )?;
    if let Some(meta) = existing {
        temp.as_file().set_permissions(meta.permissions())?;
    }
    Ok(temp)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nothing_appears_until_commit_and_nothing_stays_without_it() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.csv");
        let mut out = Output::create(&target, &[]).unwrap();
        out.write_all(b"half").unwrap();
        out.flush().unwrap();
        assert!(!target.exists());
        drop(out);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);

        let mut out = Output::create(&target, &[]).unwrap();
        out.write_all(b"whole\n").unwrap();
        out.commit().unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"whole\n");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn a_device_is_written_in_place_not_replaced() {
        let null = Path::new("/dev/null");
        let mut out = Output::create(null, &[]).unwrap();
        out.write_all(b"gone").unwrap();
        out.commit().unwrap();
        let meta = std::fs::metadata(null).unwrap();
        assert!(!meta.is_file(), "/dev/null is still a device");
    }

    #[test]
    fn a_closed_pipe_is_quiet_only_on_stdout() {
        let pipe = || io::Error::from(io::ErrorKind::BrokenPipe);
        assert!(matches!(
            Output::stdout(&[]).unwrap().error(pipe()),
            CliError::PipeClosed
        ));
        let dir = tempfile::tempdir().unwrap();
        let out = Output::create(&dir.path().join("x"), &[]).unwrap();
        assert!(matches!(out.error(pipe()), CliError::File { .. }));
    }
}
