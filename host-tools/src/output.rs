//! Where every command writes: a file that appears whole or not at all, or
//! standard output.
//!
//! A file output is written to a temporary file beside its target (same
//! directory, so the final rename stays on one file system) and renamed
//! over the target only by [`Output::commit`]. Dropping an [`Output`]
//! without committing it, on any error path, removes the temporary file
//! and leaves whatever was at the target as it was. An output that is the
//! same file as one of the command's inputs (same path, a hard link, or a
//! symlink to it: handles are compared, not names) is refused before
//! anything is created.
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

use std::io::{self, BufWriter, Stdout, Write};
use std::path::{Path, PathBuf};

use tempfile::NamedTempFile;

use crate::CliError;

/// Bytes buffered before they go to the file or pipe.
const BUFFER_LEN: usize = 1 << 16;

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
        temp: BufWriter<NamedTempFile>,
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
        let resolved = resolve_symlink(target);
        // A device or a pipe (`-o /dev/null`, a FIFO) is written as it is:
        // renaming a file over it would replace the device itself.
        if std::fs::metadata(&resolved).is_ok_and(|m| !m.is_file() && !m.is_dir()) {
            let file = std::fs::OpenOptions::new()
                .write(true)
                .open(&resolved)
                .map_err(|e| CliError::file(target, e))?;
            return Ok(Self {
                sink: Sink::Device(BufWriter::with_capacity(BUFFER_LEN, file)),
                name: target.to_path_buf(),
                pipe_closed: false,
            });
        }
        let temp = temp_beside(&resolved)
            .map_err(|e| CliError::file(target, format!("cannot create the output: {e}")))?;
        Ok(Self {
            sink: Sink::File {
                temp: BufWriter::with_capacity(BUFFER_LEN, temp),
                target: resolved,
            },
            name: target.to_path_buf(),
            pipe_closed: false,
        })
    }

    /// An output to standard output. A reader that goes away (`| head`)
    /// ends the command quietly: see [`Self::error`].
    #[must_use]
    pub fn stdout() -> Self {
        Self {
            sink: Sink::Stdout(BufWriter::with_capacity(BUFFER_LEN, io::stdout())),
            name: PathBuf::from("<stdout>"),
            pipe_closed: false,
        }
    }

    /// [`Self::create`] for `Some(target)`, else [`Self::stdout`].
    pub fn create_or_stdout(target: Option<&Path>, inputs: &[&Path]) -> Result<Self, CliError> {
        target.map_or_else(|| Ok(Self::stdout()), |t| Self::create(t, inputs))
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
                let temp = temp
                    .into_inner()
                    .map_err(|e| CliError::file(&name, e.into_error()))?;
                temp.as_file()
                    .sync_all()
                    .map_err(|e| CliError::file(&name, e))?;
                temp.persist(&target)
                    .map(drop)
                    .map_err(|e| CliError::file(&name, format!("cannot replace: {}", e.error)))
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

/// Refuses `target` if it is the same file as one of `inputs`. A target or
/// input that does not exist (yet) cannot be the same file.
fn refuse_inputs(target: &Path, inputs: &[&Path]) -> Result<(), CliError> {
    for input in inputs {
        if same_file::is_same_file(target, input).unwrap_or(false) {
            return Err(CliError::Usage(format!(
                "{}: the output is the input {}; refusing to overwrite it",
                target.display(),
                input.display()
            )));
        }
    }
    Ok(())
}

/// The file a symlink points to (so writing through the link keeps it),
/// or `target` itself.
fn resolve_symlink(target: &Path) -> PathBuf {
    let is_link = std::fs::symlink_metadata(target).is_ok_and(|m| m.file_type().is_symlink());
    if is_link {
        std::fs::canonicalize(target).unwrap_or_else(|_| target.to_path_buf())
    } else {
        target.to_path_buf()
    }
}

/// A new temporary file beside `target`, with a hidden name that says what
/// it will become, readable by others as a file the user creates would be
/// (the umask still applies).
fn temp_beside(target: &Path) -> io::Result<NamedTempFile> {
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let prefix = format!(
        ".{}.",
        target.file_name().unwrap_or_default().to_string_lossy()
    );
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    builder.tempfile_in(dir)
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
            Output::stdout().error(pipe()),
            CliError::PipeClosed
        ));
        let dir = tempfile::tempdir().unwrap();
        let out = Output::create(&dir.path().join("x"), &[]).unwrap();
        assert!(matches!(out.error(pipe()), CliError::File { .. }));
    }
}
