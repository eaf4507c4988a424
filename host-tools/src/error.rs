//! The CLI's error type and its mapping to exit codes.

use std::path::{Path, PathBuf};

/// A failure that ends a `wobblog` command.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// Bad arguments or options (exit code 2).
    #[error("{0}")]
    Usage(String),
    /// A file could not be read, written or understood (exit code 1).
    #[error("{}: {message}", crate::text::shown(path))]
    File {
        /// The file concerned.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// A runtime failure that concerns no single file, such as several logs
    /// of a multi-log command failing (exit code 1).
    #[error("{0}")]
    Failed(String),
    /// Standard output was closed by its reader (`| head`): the command
    /// ends quietly and successfully, as a filter should.
    #[error("standard output closed")]
    PipeClosed,
}

impl CliError {
    /// A runtime failure about `path`.
    pub fn file(path: &Path, message: impl std::fmt::Display) -> Self {
        Self::File {
            path: path.to_path_buf(),
            message: message.to_string(),
        }
    }

    /// The process exit code for this error.
    #[must_use]
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Usage(_) => 2,
            Self::File { .. } | Self::Failed(_) => 1,
            Self::PipeClosed => 0,
        }
    }
}
