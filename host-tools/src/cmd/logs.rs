//! What the commands that analyse many logs share: a progress bar over the
//! files, going on past a log that cannot be read, and loss warnings.

use std::io::Write;
use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressStyle};

use crate::output::Output;
use crate::summary::Summary;
use crate::CliError;

/// Calls `visit` for every log in turn behind a progress bar (drawn only on
/// a terminal and for more than one file). A log that fails is reported on
/// stderr and the rest still run; the result then names how many failed.
pub fn for_each_log(
    logs: &[PathBuf],
    message: &'static str,
    mut visit: impl FnMut(&Path) -> Result<(), CliError>,
) -> Result<(), CliError> {
    let bar = if logs.len() > 1 {
        ProgressBar::new(logs.len() as u64)
    } else {
        ProgressBar::hidden()
    };
    if let Ok(style) = ProgressStyle::with_template("{msg} {bar:40} {pos}/{len} {wide_msg}") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(message);
    let mut failed = 0usize;
    for log in logs {
        if let Err(e) = visit(log) {
            bar.suspend(|| eprintln!("wobblog: {e}"));
            failed += 1;
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    match failed {
        0 => Ok(()),
        _ => Err(CliError::Failed(format!(
            "{} of {} logs could not be read (see above); the others were processed",
            failed,
            logs.len()
        ))),
    }
}

/// Prints what a partly readable run lost, so results from it are read
/// with care.
pub fn warn_losses(log: &Path, summary: &Summary) {
    for line in summary.losses.describe() {
        eprintln!("wobblog: {}: warning: {line}", log.display());
    }
}

/// Writes `text` to standard output. A closed pipe (`| head`) ends the
/// output quietly, where `print!` would panic; other errors are reported.
pub fn print_stdout(text: &str) -> Result<(), CliError> {
    let mut out = Output::stdout();
    match out.write_all(text.as_bytes()) {
        Ok(()) => out.commit(),
        Err(e) => Err(out.error(e)),
    }
}
