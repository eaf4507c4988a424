//! What the commands that analyse many logs share: a progress bar over the
//! files, going on past a log that cannot be read, and loss warnings.

use std::io::Write;
use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressStyle};

use crate::cmd::summary::logs_in;
use crate::losses::Losses;
use crate::output::Output;
use crate::summary::Summary;
use crate::CliError;

/// The logs named by `inputs`: files as given, directories' `*.WBL` files
/// in name order (a card folder, as `summary` and `export` list it).
///
/// # Errors
/// A directory without a log, or that cannot be listed.
pub fn expand(inputs: &[PathBuf]) -> Result<Vec<PathBuf>, CliError> {
    let mut logs = Vec::new();
    for input in inputs {
        if input.is_dir() {
            let found = logs_in(input)?;
            if found.is_empty() {
                return Err(CliError::file(input, "no *.WBL logs in this directory"));
            }
            logs.extend(found);
        } else {
            logs.push(input.clone());
        }
    }
    Ok(logs)
}

/// Logs of a folder named in [`one_log`]'s error; the rest are counted.
const LOGS_LISTED: usize = 10;

/// Refuses a directory where a command takes one log (`command` names
/// it): the error names the folder and lists its logs, so the user can
/// pick one; `hint` says what to do for them all.
///
/// # Errors
/// `log` is a directory, or a directory that cannot be listed.
pub fn one_log(log: &Path, command: &str, hint: &str) -> Result<(), CliError> {
    if !log.is_dir() {
        return Ok(());
    }
    let found = logs_in(log)?;
    let mut names: Vec<String> = found
        .iter()
        .filter_map(|p| p.file_name())
        .take(LOGS_LISTED)
        .map(crate::text::shown)
        .collect();
    if found.len() > LOGS_LISTED {
        names.push(format!("and {} more", found.len() - LOGS_LISTED));
    }
    let listed = if names.is_empty() {
        "it holds no *.WBL log".to_string()
    } else {
        format!("its logs: {}", names.join(", "))
    };
    Err(CliError::file(
        log,
        format!("a directory; `wobblog {command}` takes one log ({listed}); {hint}"),
    ))
}

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

/// `--json`, or its alias `--format jsonl`: one convention for every
/// command that prints a table or JSON (`summary` and `decode` take
/// `--format` too, and `summary --json` is its `--format jsonl`).
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub struct JsonArgs {
    /// JSON (one object per line) instead of text; the same as `--format jsonl`.
    #[arg(long)]
    pub json: bool,
    /// `text` (the default) or `jsonl` (the same as `--json`).
    #[arg(long, value_enum, value_name = "FORMAT")]
    pub format: Option<TextOrJsonl>,
}

/// The `--format` of a command that prints text or JSON.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TextOrJsonl {
    /// Text for reading.
    Text,
    /// One JSON object per line.
    Jsonl,
}

impl JsonArgs {
    /// Whether JSON is asked for.
    ///
    /// # Errors
    /// `--json` with `--format text`.
    pub fn is_json(&self) -> Result<bool, CliError> {
        match (self.json, self.format) {
            (true, Some(TextOrJsonl::Text)) => {
                Err(CliError::Usage("--json contradicts --format text".into()))
            }
            (json, format) => Ok(json || format == Some(TextOrJsonl::Jsonl)),
        }
    }
}

/// Loss warnings printed per log; `info` and `events` list the rest.
const WARNINGS_SHOWN: usize = 10;

/// Prints what a partly readable run lost, so results from it are read
/// with care.
pub fn warn_losses(log: &Path, summary: &Summary) {
    for line in warnings(&summary.losses) {
        eprintln!("wobblog: {}: warning: {line}", crate::text::shown(log));
    }
}

/// The first [`WARNINGS_SHOWN`] lines of what `losses` describes, then one
/// line pointing to the rest: a log damaged all through must not flood the
/// terminal.
pub fn warnings(losses: &Losses) -> Vec<String> {
    let mut lines = losses.describe();
    if lines.len() > WARNINGS_SHOWN {
        lines.truncate(WARNINGS_SHOWN);
        lines.push(
            "more losses not shown here: `wobblog info` counts them all, `wobblog events` lists them"
                .to_string(),
        );
    }
    lines
}

/// Writes `text` to `out` (standard output, made by [`Output::stdout`]
/// with the command's inputs before its work) and commits it. A closed
/// pipe (`| head`) ends the output quietly, where `print!` would panic;
/// other errors are reported.
pub fn print(mut out: Output, text: &str) -> Result<(), CliError> {
    match out.write_all(text.as_bytes()) {
        Ok(()) => out.commit(),
        Err(e) => Err(out.error(e)),
    }
}

/// Writes `value` to `out` as one line of JSON as it is serialised
/// ([`crate::text::write_json_line`]), then commits it.
pub fn print_json(mut out: Output, value: &impl serde::Serialize) -> Result<(), CliError> {
    match crate::text::write_json_line(std::io::BufWriter::new(&mut out), value) {
        Ok(()) => out.commit(),
        Err(e) => Err(out.error(e)),
    }
}
