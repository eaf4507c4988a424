//! `wobblog selftest`: the logger's field self-test report (`SELFTEST.TXT`
//! on the card), one check per line, failures first in the summary; the
//! exit code is 1 when a check failed.

use std::path::PathBuf;

use wobble_core::selftest::{read_report, Verdict};

use crate::cmd::logs::print;
use crate::output::Output;
use crate::text::escape_controls;
use crate::CliError;

/// Arguments of `wobblog selftest`.
#[derive(clap::Args)]
pub struct Args {
    /// The report (`SELFTEST.TXT` from the card).
    pub report: PathBuf,
}

/// Runs `wobblog selftest`.
pub fn run(args: &Args) -> Result<(), CliError> {
    let stdout = Output::stdout(&[&args.report])?;
    let bytes = std::fs::read(&args.report).map_err(|e| CliError::file(&args.report, e))?;
    let text =
        std::str::from_utf8(&bytes).map_err(|_| CliError::file(&args.report, "not UTF-8 text"))?;
    let mut out = String::new();
    let mut failed = Vec::new();
    read_report(text, &mut |line| {
        let verdict = match line.verdict {
            Verdict::Pass => "pass",
            Verdict::Fail => {
                failed.push(escape_controls(line.check).into_owned());
                "FAIL"
            }
        };
        out.push_str(&format!(
            "{:<9} {verdict:<4}  {}\n",
            escape_controls(line.check),
            escape_controls(line.detail)
        ));
    })
    .map_err(|e| CliError::file(&args.report, e))?;
    out.push_str(&if failed.is_empty() {
        "all checks passed: ready to ride\n".to_owned()
    } else {
        format!(
            "failed: {} (see firmware/docs/board.md, bring-up)\n",
            failed.join(", ")
        )
    });
    print(stdout, &out)?;
    // A failed check is a failure of the command, so scripts can tell.
    if failed.is_empty() {
        Ok(())
    } else {
        Err(CliError::file(
            &args.report,
            format!("{} failed", crate::words::plural(failed.len(), "check")),
        ))
    }
}
