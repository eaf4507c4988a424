//! `wobblog margin --mode weave`: the weave speed (where the weave turns
//! stable) predicted from kicks above it (`analysis::margin::weave`), as a
//! table in words or one JSON object.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::analysis::campaign_kicks::Prefer;
use crate::analysis::kicks::Kick;
use crate::analysis::margin::weave::{predict_weave, WeaveMargin};
use crate::analysis::margin::KickPoint;
use crate::analysis::weave::load_weave_kicks;
use crate::cmd::logs::{for_each_log, print, print_json, warn_losses};
use crate::cmd::margin::{kick_table, speed_text, Args, KickLine};
use crate::output::Output;
use crate::CliError;

/// One weave kick as reported.
#[derive(Clone, Debug, Serialize)]
pub struct WeaveKickRow {
    /// The log it is in.
    pub log: String,
    /// The kick, measured in the roll rate (`amp_deg`: the roll angle's
    /// amplitude).
    #[serde(flatten)]
    pub kick: Kick,
    /// Whether the regression used it.
    pub used: bool,
}

/// What `wobblog margin --mode weave` prints.
#[derive(Serialize)]
pub struct WeaveReport {
    /// `weave`.
    pub mode: &'static str,
    /// The prediction.
    #[serde(flatten)]
    pub margin: WeaveMargin,
    /// Every kick, in the order of the logs.
    pub kicks: Vec<WeaveKickRow>,
}

/// The options `--mode weave` cannot take, named.
fn refuse_options(args: &Args) -> Result<(), CliError> {
    let refused = [
        (args.plot.is_some(), "--plot"),
        (args.model.is_some(), "--model"),
        (
            args.kicks == Prefer::Card,
            "--kicks card (the board records wobble kicks only)",
        ),
    ];
    match refused.iter().find(|r| r.0) {
        Some((_, what)) => Err(CliError::Usage(format!(
            "--mode weave does not take {what}: the weave's margin is the host's kicks and the \
             prediction alone"
        ))),
        None => Ok(()),
    }
}

/// The weave report of `logs`, and whether every log was read.
pub fn weave_campaign(logs: &[PathBuf], args: &Args) -> (WeaveReport, Result<(), CliError>) {
    let mut rows = Vec::new();
    let result = for_each_log(logs, "measuring weave kicks", |log| {
        let (summary, kicks) = load_weave_kicks(log)?;
        warn_losses(log, &summary);
        let name = log.display().to_string();
        rows.extend(kicks.into_iter().map(|kick| WeaveKickRow {
            log: name.clone(),
            kick,
            used: false,
        }));
        Ok(())
    });
    let points: Vec<KickPoint> = rows.iter().map(|r| KickPoint::from(&r.kick)).collect();
    let margin = predict_weave(&points, args.trend);
    for (row, w) in rows.iter_mut().zip(&margin.fit.weights) {
        row.used = *w > 0.0;
    }
    let report = WeaveReport {
        mode: "weave",
        margin,
        kicks: rows,
    };
    (report, result)
}

/// Runs `wobblog margin --mode weave` on `logs`.
pub fn run(args: &Args, logs: &[PathBuf]) -> Result<(), CliError> {
    refuse_options(args)?;
    let inputs: Vec<&Path> = logs.iter().map(PathBuf::as_path).collect();
    let stdout = Output::stdout(&inputs)?;
    let (report, result) = weave_campaign(logs, args);
    if report.kicks.is_empty() && result.is_err() {
        return result;
    }
    let printed = if args.json {
        print_json(stdout, &report)
    } else {
        print(stdout, &render_text(&report, logs.len()))
    };
    result.and(printed)
}

/// The table form: the answer in words, then every kick.
fn render_text(r: &WeaveReport, logs: usize) -> String {
    use std::fmt::Write;
    let m = &r.margin;
    let mut o = String::new();
    let _ = writeln!(
        o,
        "{} in {}: {} used, {} rejected",
        crate::words::plural(r.kicks.len(), "weave kick"),
        crate::words::plural(logs, "log"),
        m.kicks_used,
        m.kicks_rejected
    );
    match (m.weave_speed_mps, m.ci95_mps) {
        (Some(v), [lo, hi]) => {
            let _ = writeln!(
                o,
                "predicted weave speed {v:.2} m/s (the weave is stable above it), 95 % interval \
                 {} to {}",
                speed_text(lo, "unbounded (the data cannot bound it)"),
                speed_text(hi, "unbounded")
            );
        }
        (None, [_, Some(hi)]) => {
            let _ = writeln!(
                o,
                "no predicted weave speed; the data only say it is below {hi:.2} m/s"
            );
        }
        (None, _) => {
            let _ = writeln!(o, "no predicted weave speed");
        }
    }
    for w in &m.warnings {
        let _ = writeln!(o, "warning: {w}");
    }
    let lines = r.kicks.iter().map(|k| KickLine {
        values: [
            k.kick.t_s,
            k.kick.speed_mps,
            k.kick.freq_hz,
            k.kick.sigma_per_s,
            k.kick.sigma_sd_per_s,
            k.kick.amp_deg,
        ],
        source: None,
        used: k.used,
        log: &k.log,
    });
    kick_table(&mut o, ("roll_deg", 3), lines);
    o
}
