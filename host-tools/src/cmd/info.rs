//! `wobblog info`: what a log holds and what it lost.

use std::path::{Path, PathBuf};

use crate::cmd::logs::{expand, for_each_log, print};
use crate::output::Output;
use crate::reader::read_log;
use crate::summary::{Summary, SummaryBuilder};
use crate::text::escape_controls;
use crate::CliError;

/// Arguments of `wobblog info`.
#[derive(clap::Args)]
pub struct Args {
    /// Card logs (`RUNnnnnn.WBL`) or card folders (every `*.WBL` at their
    /// top, in name order): each log's report in turn.
    #[arg(required = true, value_name = "LOGS|DIRS")]
    pub logs: Vec<PathBuf>,
    /// `--json` (or `--format jsonl`) for JSON instead of text.
    #[command(flatten)]
    pub output: crate::cmd::logs::JsonArgs,
}

/// One log's JSON among several: its summary with the log named first, as
/// `wobble --json` names its log.
#[derive(serde::Serialize)]
struct NamedSummary<'a> {
    log: String,
    #[serde(flatten)]
    summary: &'a Summary,
}

/// Runs `wobblog info`. One log is reported as ever (JSON as one indented
/// object); several in turn, text reports apart by a blank line and JSON as
/// JSON lines naming their log, a log that cannot be read named on stderr
/// and the rest still reported (exit code 1), as `wobble` does.
pub fn run(args: &Args) -> Result<(), CliError> {
    let json = args.output.is_json()?;
    let logs = crate::inputs::distinct(expand(&args.logs)?);
    let inputs: Vec<&Path> = logs.iter().map(PathBuf::as_path).collect();
    let stdout = Output::stdout(&inputs)?;
    if let [log] = logs.as_slice() {
        let summary = summarise(log)?;
        let text = if json {
            let text =
                serde_json::to_string_pretty(&summary).map_err(|e| CliError::file(log, e))?;
            crate::text::json_terminal_safe(text) + "\n"
        } else {
            render(log, &summary)
        };
        return print(stdout, &text);
    }
    let mut text = String::new();
    let result = for_each_log(&logs, "reading", |log| {
        let summary = summarise(log)?;
        text.push_str(&report_among(log, &summary, json, text.is_empty())?);
        Ok(())
    });
    let printed = print(stdout, &text);
    result.and(printed)
}

/// The report of one of several logs: a JSON line naming it, or its text
/// after a blank line unless it comes `first`.
fn report_among(
    log: &Path,
    summary: &Summary,
    json: bool,
    first: bool,
) -> Result<String, CliError> {
    if json {
        let named = NamedSummary {
            log: log.display().to_string(),
            summary,
        };
        let line = serde_json::to_string(&named).map_err(|e| CliError::file(log, e))?;
        return Ok(crate::text::json_terminal_safe(line) + "\n");
    }
    let gap = if first { "" } else { "\n" };
    Ok(format!("{gap}{}", render(log, summary)))
}

/// Decodes the log at `path` into a summary.
pub fn summarise(path: &std::path::Path) -> Result<Summary, CliError> {
    let mut builder = SummaryBuilder::new();
    let stats = read_log(path, |event| builder.observe(&event))?;
    Ok(builder.finish(&stats))
}

fn render(path: &std::path::Path, s: &Summary) -> String {
    use std::fmt::Write;
    let mut o = String::new();
    let opt = |v: &Option<String>| {
        v.as_deref()
            .map_or_else(|| "unknown".into(), |t| escape_controls(t).into_owned())
    };
    let _ = writeln!(o, "log:          {}", crate::text::shown(path));
    let _ = writeln!(
        o,
        "firmware:     {}  device {}  run {}",
        opt(&s.firmware),
        opt(&s.device_id),
        s.run.map_or("?".into(), |r| r.to_string())
    );
    let span = match (s.start_s, s.end_s) {
        (Some(a), Some(b)) if s.segments > 1 => format!(
            "{} segments between time jumps, first frame {a:.3} s, last {b:.3} s since boot",
            s.segments
        ),
        (Some(a), Some(b)) => format!("{a:.3} s to {b:.3} s since boot"),
        _ => "no frames".into(),
    };
    let _ = writeln!(o, "duration:     {:.2} s ({span})", s.duration_s);
    if s.time_jumps + s.forward_time_jumps > 0 {
        let _ = writeln!(
            o,
            "time jumps:   {} back, {} forward (listed under losses)",
            s.time_jumps, s.forward_time_jumps
        );
    }
    let _ = writeln!(
        o,
        "samples:      {} at {} Hz",
        s.samples,
        s.sample_rate_hz.unwrap_or(100)
    );
    let dropouts: Vec<String> = s.dropouts.iter().map(|(k, v)| format!("{v} {k}")).collect();
    let _ = writeln!(
        o,
        "dropouts:     {} frames dropped by the logger{}",
        s.frames_dropped,
        if dropouts.is_empty() {
            String::new()
        } else {
            format!(" ({})", dropouts.join(", "))
        }
    );
    let _ = writeln!(
        o,
        "lost blocks:  {} ({} frames), {} damaged, {} bytes skipped",
        s.lost_blocks, s.frames_lost, s.damaged_blocks, s.bytes_skipped
    );
    if s.unwritten_blocks > 0 {
        let _ = writeln!(
            o,
            "unwritten:    {} blocks of zeros (space reserved or never written: no data lost)",
            s.unwritten_blocks
        );
    }
    if s.repeated_blocks + s.out_of_range > 0 {
        let _ = writeln!(
            o,
            "invalid:      {} copies of blocks skipped (decoded once), {} impossible values dropped, replaced or flagged",
            s.repeated_blocks, s.out_of_range
        );
    }
    let _ = writeln!(
        o,
        "gps:          {} fixes, {:.1} % of samples with a position",
        s.gps_fixes, s.gps_coverage_pct,
    );
    let _ = writeln!(
        o,
        "utc:          {} to {} (frames, through the GPS sync pairs)",
        opt(&s.first_utc),
        opt(&s.last_utc)
    );
    let _ = writeln!(o, "records:      kind              count    per s");
    for (kind, n) in &s.records {
        let rate = n.rate_hz.map_or("-".into(), |r| format!("{r:.3}"));
        let _ = writeln!(o, "  {kind:<24}{:>11}  {rate:>7}", n.count);
    }
    let _ = writeln!(o, "alerts:       {}", s.alerts.len());
    for a in &s.alerts {
        let off = a.off_s.map_or("end of log".into(), |t| format!("{t:.2} s"));
        let _ = writeln!(
            o,
            "  {:.2} s to {off}: {:.2} Hz, {:.2} deg",
            a.on_s, a.freq_hz, a.amp_deg
        );
    }
    let _ = writeln!(o, "markers:      {}", s.markers.len());
    let _ = writeln!(o, "kicks:        {} ring-downs measured on board", s.kicks);
    let faults: Vec<String> = s.faults.iter().map(|(k, v)| format!("{k} {v}")).collect();
    let _ = writeln!(
        o,
        "faults:       {}",
        if faults.is_empty() {
            "none".into()
        } else {
            faults.join(", ")
        }
    );
    let _ = writeln!(o, "config:       {} lines", s.config.len());
    for line in &s.config {
        let _ = writeln!(o, "  {}", escape_controls(line));
    }
    let losses = s.losses.describe();
    if !losses.is_empty() {
        let _ = writeln!(o, "losses:");
        for line in losses {
            let _ = writeln!(o, "  {line}");
        }
    }
    o
}
