//! `wobblog config`: the `CONFIG.TXT` a log was recorded with, from its
//! header, ready to copy back to a card.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use wobble_core::config::Config;
use wobble_core::format::{DecodeStats, Event, Record, BLOCK_LEN};

use crate::cmd::logs::print;
use crate::output::Output;
use crate::reader::read_log_until;
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
    // One log's settings, ready for one card: a folder is refused with its logs.
    crate::cmd::logs::one_log(&args.log, "config", "pick the run whose settings to copy")?;
    let stdout = Output::stdout(&[&args.log])?;
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
            crate::text::shown(&args.log),
            faults.first().len()
        );
    }
    print(stdout, &header.config_text(&args.log))
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
            || crate::text::shown(log),
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

/// Bytes `config` reads first: the header of a default configuration
/// fills about two blocks.
const HEADER_CHUNK_LEN: usize = 8 * BLOCK_LEN;

/// Reads the header records of the log at `path`: it stops at the first
/// record that is not one (the header comes first), so a large log costs
/// no more than a small one.
pub fn read_header(path: &Path) -> Result<Header, CliError> {
    scan_header(path).map(|(header, _)| header)
}

/// The header, and how much of the log was decoded to find it.
fn scan_header(path: &Path) -> Result<(Header, DecodeStats), CliError> {
    let mut header = Header::default();
    let stats = read_log_until(path, HEADER_CHUNK_LEN, |event| match event {
        Event::Record(Record::LogInfo(info)) => {
            header.firmware = Some(info.firmware.to_string());
            header.run = Some(info.run);
            ControlFlow::Continue(())
        }
        Event::Record(Record::Config(line)) => {
            header.config.push(line.text.to_string());
            ControlFlow::Continue(())
        }
        Event::Record(Record::Channel(_)) => ControlFlow::Continue(()),
        Event::Record(_) => ControlFlow::Break(()),
        // Damage before the first record is skipped like anywhere else.
        _ => ControlFlow::Continue(()),
    })?;
    Ok((header, stats))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reader::tests::log;

    #[test]
    fn the_header_is_read_and_the_rest_is_not() {
        let (file, lines) = log(60_000, 0);
        let blocks = std::fs::metadata(file.path()).unwrap().len() / BLOCK_LEN as u64;
        let (header, stats) = scan_header(file.path()).unwrap();
        assert_eq!(header.config, lines);
        assert_eq!(header.run, Some(12));
        assert_eq!(header.firmware.as_deref(), Some("test"));
        // The first chunk holds the header and the first frames.
        assert!(stats.blocks > 0 && stats.blocks <= 8, "{stats:?}");
        assert!(blocks > 100, "{blocks} blocks");
    }

    #[test]
    fn damage_before_the_header_is_skipped() {
        let (file, lines) = log(100, 3000);
        let (header, stats) = scan_header(file.path()).unwrap();
        assert_eq!(header.config, lines);
        assert_eq!(stats.bytes_skipped, 3000);
    }

    #[test]
    fn a_log_of_header_only_is_read_to_its_end() {
        let (file, lines) = log(0, 0);
        assert_eq!(read_header(file.path()).unwrap().config, lines);
    }
}
