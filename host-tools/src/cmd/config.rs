//! `wobblog config`: the `CONFIG.TXT` a log was recorded with, from its
//! header, ready to copy back to a card.

use std::path::{Path, PathBuf};

use wobble_core::config::Config;
use wobble_core::format::{Event, Record};

use crate::cmd::logs::print_stdout;
use crate::reader::read_log;
use crate::text::escape_controls;
use crate::CliError;

/// Arguments of `wobblog config`.
#[derive(clap::Args)]
pub struct Args {
    /// The card log (`RUNnnnnn.WBL`).
    pub log: PathBuf,
}

/// Runs `wobblog config`.
pub fn run(args: &Args) -> Result<(), CliError> {
    let header = read_header(&args.log)?;
    if header.config.is_empty() {
        return Err(CliError::file(
            &args.log,
            "the header holds no configuration lines (a log built by `wobblog encode`, or its header was lost)",
        ));
    }
    let faults = Config::parse(header.config.join("\n").as_bytes()).faults;
    if !faults.is_empty() {
        eprintln!(
            "wobblog: {}: warning: {} configuration lines this version does not accept as they are",
            args.log.display(),
            faults.first().len()
        );
    }
    print_stdout(&header.config_text(&args.log))
}

/// What a log's header says about how it was recorded.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Header {
    /// Firmware version.
    pub firmware: Option<String>,
    /// Run number on the card.
    pub run: Option<u32>,
    /// The `key=value` lines of the configuration in force.
    pub config: Vec<String>,
}

impl Header {
    /// The configuration as a `CONFIG.TXT`: a comment naming the log, then
    /// one line per key.
    #[must_use]
    pub fn config_text(&self, log: &Path) -> String {
        let name = log.file_name().map_or_else(
            || log.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        let mut text = format!(
            "# CONFIG.TXT in force for {name} (run {}, firmware {})\n",
            self.run.map_or("?".into(), |r| r.to_string()),
            escape_controls(self.firmware.as_deref().unwrap_or("unknown")),
        );
        for line in &self.config {
            text.push_str(&escape_controls(line));
            text.push('\n');
        }
        text
    }
}

/// Reads the header records of the log at `path`.
///
/// The header comes first, so reading stops being interesting after it;
/// the whole file is still read to keep one code path for damage reports.
pub fn read_header(path: &Path) -> Result<Header, CliError> {
    let mut header = Header::default();
    read_log(path, |event| match event {
        Event::Record(Record::LogInfo(info)) => {
            header.firmware = Some(info.firmware.to_string());
            header.run = Some(info.run);
        }
        Event::Record(Record::Config(line)) => header.config.push(line.text.to_string()),
        _ => {}
    })?;
    Ok(header)
}
