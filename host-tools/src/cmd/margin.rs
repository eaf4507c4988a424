//! `wobblog margin`: the wobble speed predicted from a kick-test campaign
//! below it (damping extrapolation, `analysis::margin`), with its 95 %
//! interval, as a table in words or one JSON object, and the damping trend
//! as a figure.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::analysis::campaign_kicks::{load_campaign_kicks, CampaignKick, Prefer};
use crate::analysis::kicks::KickMode;
use crate::analysis::margin::{predict_with, KickPoint, Margin, Trend, RIDE_MARGIN};
use crate::cmd::logs::{expand, for_each_log, print, print_json, warn_losses};
use crate::cmd::margin_model::{estimate, ModelEstimate, DEFAULT_PARAMS};
use crate::output::Output;
use crate::plot::margin::{KickDot, MarginPlot};
use crate::plot::{render, ImageKind};
use crate::CliError;

/// Arguments of `wobblog margin`.
#[derive(clap::Args)]
pub struct Args {
    /// Card logs (`RUNnnnnn.WBL`) or directories of them: every kick of
    /// every log is one point of the campaign.
    #[arg(required = true, value_name = "LOGS|DIRS")]
    pub inputs: Vec<PathBuf>,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Draw sigma against speed with every kick, the fit and its band and
    /// the predicted crossing into this `.png` or `.svg` file.
    #[arg(long, value_name = "OUT")]
    pub plot: Option<PathBuf>,
    /// Also fit the wobble model of this parameter file to the kicks and
    /// give the fitted model's wobble speed with its interval.
    #[arg(long, value_name = "PARAMS")]
    pub model: Option<PathBuf>,
    /// A parameter to fit with `--model` (repeat; default the steering
    /// head's stiffness and damping).
    #[arg(long = "param", value_name = "KEY", requires = "model")]
    pub params: Vec<String>,
    /// Which kick measurements to use: `best` (the card's kick records,
    /// re-measured by the host from the steering signal; the host's own
    /// where the card has none, the card's where the host finds none),
    /// `card` (only the card's records) or `host` (only the host's).
    #[arg(long, value_enum, default_value_t = Prefer::Best)]
    pub kicks: Prefer,
    /// The trend of sigma against speed: `line` (a line bent by a shape
    /// relative to the wobble speed, its interval allowing for a different
    /// bend beyond the kicks) or `quadratic`
    /// (fitted to the kicks alone: worse on the simulated campaigns).
    #[arg(long, value_enum, default_value_t = Trend::Line)]
    pub trend: Trend,
    /// The riding margin, per cent of the lower bound: the riding limit
    /// (`ride_below_mps`) is the lower bound less this much.
    #[arg(long, value_name = "PERCENT", default_value_t = 100.0 * RIDE_MARGIN,
          value_parser = parse_percent)]
    pub ride_margin: f64,
    /// The mode whose critical speed is predicted: `wobble` (from kicks
    /// below the wobble speed, in the steering angle) or `weave` (the
    /// weave speed, where the weave turns stable, from kicks above it, in
    /// the roll rate; the host's kicks only, no `--plot` or `--model`).
    #[arg(long, value_enum, default_value_t = KickMode::Wobble)]
    pub mode: KickMode,
    /// The figure's size and resolution (`--size`, `--dpi`).
    #[command(flatten)]
    pub figure: crate::plot::FigureArgs,
}

/// A riding margin in per cent: a number from 0 to 90.
fn parse_percent(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if (0.0..=90.0).contains(&v) => Ok(v),
        _ => Err(format!("{text} is not a per cent from 0 to 90")),
    }
}

/// One kick as reported.
#[derive(Clone, Debug, Serialize)]
pub struct KickRow {
    /// The log it is in.
    pub log: String,
    /// The kick: where its values come from (`source`: `card`, `host` or
    /// `card-host`), the values, and the host's fit and the card's record
    /// behind them.
    #[serde(flatten)]
    pub kick: CampaignKick,
    /// Whether the regression used it (an outlier gets no weight).
    pub used: bool,
}

/// What `wobblog margin` prints.
#[derive(Serialize)]
pub struct Report {
    /// Predicted wobble speed, m/s (`null` when the kicks give none).
    pub wobble_speed_mps: Option<f64>,
    /// Its 95 % interval `[lo, hi]`, `hi` null when the data cannot bound it.
    pub ci95_mps: [Option<f64>; 2],
    /// Why the interval is open above, when it is.
    pub open_because: Option<String>,
    /// The riding limit: the lower bound less the riding margin (null
    /// without a lower bound).
    pub ride_below_mps: Option<f64>,
    /// The riding margin, a fraction of the lower bound.
    pub ride_margin: f64,
    /// The highest speed for the next pass (null without a riding limit).
    pub next_pass_max_mps: Option<f64>,
    /// Kicks the fit used.
    pub kicks_used: usize,
    /// Kicks it rejected.
    pub kicks_rejected: usize,
    /// How the prediction and interval were made.
    pub method: String,
    /// Speeds of the kicks used, m/s.
    pub speed_range_mps: Option<[f64; 2]>,
    /// The trend fitted (`quadratic` or `line`).
    pub trend: Trend,
    /// Its coefficients `[a, b, c]` of `sigma = a + b u + c u^2` (1/s,
    /// speed in m/s; for the line `c` is not fitted but half the curvature
    /// it assumes).
    pub coefficients: Option<Vec<f64>>,
    /// The kicks' scatter about the trend over what their uncertainties
    /// say (variance of unit weight; the interval is widened by it when
    /// above 1).
    pub unit_variance: Option<f64>,
    /// The between-kick SD of the true damping, 1/s (added to each kick's
    /// own SD in the weights and the interval).
    pub between_kick_sd_per_s: Option<f64>,
    /// Why the answer is weaker than it looks.
    pub warnings: Vec<String>,
    /// Every kick, in the order of the logs.
    pub kicks: Vec<KickRow>,
    /// The model-informed estimate, with `--model`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model: Option<ModelEstimate>,
}

/// Every kick of `log`: its kick records and what the host measures from
/// its steering signal with the wheel the log was recorded with, taken as
/// `prefer` says.
fn kicks_of(log: &Path, prefer: Prefer) -> Result<Vec<CampaignKick>, CliError> {
    let (summary, kicks) = load_campaign_kicks(log, prefer)?;
    warn_losses(log, &summary);
    Ok(kicks)
}

/// Gathers the kicks of `logs` behind a progress bar; a log that cannot be
/// read is reported and the rest still count.
fn gather(logs: &[PathBuf], prefer: Prefer) -> (Vec<KickRow>, Result<(), CliError>) {
    let mut rows = Vec::new();
    let result = for_each_log(logs, "measuring kicks", |log| {
        let name = log.display().to_string();
        rows.extend(kicks_of(log, prefer)?.into_iter().map(|kick| KickRow {
            log: name.clone(),
            kick,
            used: false,
        }));
        Ok(())
    });
    (rows, result)
}

/// The report of `rows` and the prediction made from them.
#[must_use]
pub fn report(mut rows: Vec<KickRow>, trend: Trend, ride_margin: f64) -> (Report, Margin) {
    let points: Vec<KickPoint> = rows.iter().map(|r| KickPoint::from(&r.kick)).collect();
    let mut margin = predict_with(&points, trend);
    margin.set_riding_margin(ride_margin);
    for (row, w) in rows.iter_mut().zip(&margin.weights) {
        row.used = *w > 0.0;
    }
    let report = Report {
        wobble_speed_mps: margin.wobble_speed_mps,
        ci95_mps: margin.ci95_mps,
        open_because: margin.open_because.clone(),
        ride_below_mps: margin.advice.ride_below_mps,
        ride_margin: margin.advice.margin_fraction,
        next_pass_max_mps: margin.advice.next_pass_max_mps,
        kicks_used: margin.kicks_used,
        kicks_rejected: margin.kicks_rejected,
        method: margin.method.clone(),
        speed_range_mps: margin.speed_range_mps,
        trend: margin.trend,
        coefficients: margin.coefficients.clone(),
        unit_variance: margin.unit_variance,
        between_kick_sd_per_s: margin.between_kick_sd_per_s,
        warnings: margin.warnings.clone(),
        kicks: rows,
        model: None,
    };
    (report, margin)
}

/// The report of `rows` as `args` ask for it, the model's estimate
/// included with `--model` (the Python package's `wobblog.margin` too).
///
/// # Errors
/// The model's parameter file cannot be read or fitted.
pub fn full_report(rows: Vec<KickRow>, args: &Args) -> Result<(Report, Margin), CliError> {
    let (mut report, margin) = report(rows, args.trend, args.ride_margin / 100.0);
    if let Some(params) = &args.model {
        add_model(&mut report, params, &args.params)?;
    }
    Ok((report, margin))
}

/// Runs `wobblog margin`.
pub fn run(args: &Args) -> Result<(), CliError> {
    if let Some(plot) = &args.plot {
        ImageKind::of(plot)?;
    }
    let logs = crate::inputs::distinct(expand(&args.inputs)?);
    if args.mode == KickMode::Weave {
        return crate::cmd::margin_weave::run(args, &logs);
    }
    let mut inputs: Vec<&Path> = logs.iter().map(PathBuf::as_path).collect();
    if let Some(params) = &args.model {
        inputs.push(params);
    }
    let plot_out = args
        .plot
        .as_deref()
        .map(|p| Output::create(p, &inputs))
        .transpose()?;
    let stdout = Output::stdout(&inputs)?;
    let (rows, result) = gather(&logs, args.kicks);
    if rows.is_empty() && result.is_err() {
        return result;
    }
    let (report, margin) = full_report(rows, args)?;
    let printed = if args.json {
        print_json(stdout, &report)
    } else {
        print(stdout, &render_text(&report, logs.len()))
    };
    // Drawn only when every log was read: a failed command leaves an old
    // figure as it was.
    if let (Some(out), Ok(())) = (plot_out, &result) {
        render(&figure(&report, margin), out, &args.figure)?;
    }
    result.and(printed)
}

/// The campaign of `logs` as `wobblog margin` reports it (its kicks taken
/// as `prefer` says, the trend, the riding margin as a fraction), with the
/// model of `params` fitted when given (`keys`: the parameters to fit,
/// empty for the default ones). The outer error is a model that cannot be
/// fitted; the inner result says whether every log was read.
pub fn campaign(
    logs: &[PathBuf],
    prefer: Prefer,
    trend: Trend,
    ride_margin: f64,
    params: Option<&Path>,
    keys: &[String],
) -> Result<(Report, Margin, Result<(), CliError>), CliError> {
    let (rows, result) = gather(logs, prefer);
    let (report, margin) = campaign_of(rows, trend, ride_margin, params, keys)?;
    Ok((report, margin, result))
}

/// The report of the kicks `rows` and the prediction made from them, with
/// the model in `params` fitted to them (its `keys`) when given: what
/// [`campaign`] makes of the kicks it gathers.
///
/// # Errors
/// The model's parameter file cannot be read or fitted.
pub fn campaign_of(
    rows: Vec<KickRow>,
    trend: Trend,
    ride_margin: f64,
    params: Option<&Path>,
    keys: &[String],
) -> Result<(Report, Margin), CliError> {
    let (mut report, margin) = report(rows, trend, ride_margin);
    if let Some(params) = params {
        add_model(&mut report, params, keys)?;
    }
    Ok((report, margin))
}

/// Fits `keys` (the default ones when empty) of the model in `params` to
/// the kicks `report` used.
fn add_model(report: &mut Report, params: &Path, keys: &[String]) -> Result<(), CliError> {
    let keys: Vec<String> = if keys.is_empty() {
        DEFAULT_PARAMS.iter().map(|k| (*k).to_owned()).collect()
    } else {
        keys.to_vec()
    };
    let used: Vec<(f64, f64, f64, f64)> = report
        .kicks
        .iter()
        .filter(|r| r.used)
        .map(|r| {
            let k = &r.kick;
            (k.speed_mps, k.freq_hz, k.sigma_per_s, k.sigma_sd_per_s)
        })
        .collect();
    report.model = Some(estimate(params, &keys, &used, report.kicks_rejected)?);
    Ok(())
}

/// The damping-trend figure of `report` and its prediction `margin`.
#[must_use]
pub fn figure(report: &Report, margin: Margin) -> MarginPlot {
    MarginPlot {
        kicks: report
            .kicks
            .iter()
            .map(|r| KickDot {
                speed_mps: r.kick.speed_mps,
                sigma_per_s: r.kick.sigma_per_s,
                sd_per_s: r.kick.sigma_sd_per_s,
                used: r.used,
            })
            .collect(),
        margin,
        model_curve: report.model.as_ref().map(|m| m.curve.clone()),
        model_speed: report
            .model
            .as_ref()
            .and_then(|m| m.wobble_speed_mps.map(|w| (w, m.ci95_mps))),
    }
}

/// `v` to two decimals, or `what` for none.
pub(crate) fn speed_text(v: Option<f64>, what: &str) -> String {
    v.map_or(what.into(), |v| format!("{v:.2} m/s"))
}

/// The table form: the answer in words, then every kick.
/// Names and keys that come from files or the command line are shown with
/// control and bidirectional characters escaped.
fn render_text(r: &Report, logs: usize) -> String {
    let mut o = answer_text(r, logs);
    let lines = r.kicks.iter().map(|k| KickLine {
        values: [
            k.kick.t_s,
            k.kick.speed_mps,
            k.kick.freq_hz,
            k.kick.sigma_per_s,
            k.kick.sigma_sd_per_s,
            k.kick.amp_deg,
        ],
        source: Some(k.kick.source.as_str()),
        used: k.used,
        log: &k.log,
    });
    kick_table(&mut o, ("amp_deg", 2), lines);
    o
}

/// One kick of a table: t_s, speed_mps, freq_hz, sigma_per_s,
/// sigma_sd_per_s and the amplitude; where its values come from (the
/// wobble's kicks); whether the trend used it; its log.
pub(crate) struct KickLine<'a> {
    pub values: [f64; 6],
    pub source: Option<&'a str>,
    pub used: bool,
    pub log: &'a str,
}

/// Appends the table of `lines` (nothing for none) to `o`: the amplitude
/// named `amp_name`, frequencies to `freq_decimals`, a `source` column when
/// the lines have one.
pub(crate) fn kick_table<'a>(
    o: &mut String,
    (amp_name, freq_decimals): (&str, usize),
    lines: impl Iterator<Item = KickLine<'a>>,
) {
    use crate::text::escape_controls;
    use std::fmt::Write;
    let mut lines = lines.peekable();
    let Some(first) = lines.peek() else {
        return;
    };
    let source = if first.source.is_some() {
        "  source   "
    } else {
        ""
    };
    let _ = writeln!(
        o,
        "  t_s       speed_mps  freq_hz  sigma_per_s  sigma_sd_per_s  {amp_name}{source}  used  log"
    );
    let amp_width = amp_name.len();
    for k in lines {
        let [t, speed, freq, sigma, sd, amp] = k.values;
        let source = k.source.map_or(String::new(), |s| format!("  {s:9}"));
        let _ = writeln!(
            o,
            "  {t:8.2}  {speed:9.2}  {freq:7.freq_decimals$}  {sigma:11.3}  {sd:14.3}  \
             {amp:amp_width$.2}{source}  {:4}  {}",
            if k.used { "yes" } else { "no" },
            escape_controls(k.log)
        );
    }
}

/// The answer in words, as the table form begins: the kicks counted, the
/// predicted wobble speed and its interval, the riding limit, the trend,
/// the warnings and the model's estimate.
#[must_use]
pub fn answer_text(r: &Report, logs: usize) -> String {
    use crate::text::escape_controls;
    use std::fmt::Write;
    let mut o = String::new();
    let kicks = crate::words::plural(r.kicks.len(), "kick");
    let _ = writeln!(
        o,
        "{kicks} in {}: {} used, {} rejected",
        crate::words::plural(logs, "log"),
        r.kicks_used,
        r.kicks_rejected
    );
    match (r.wobble_speed_mps, r.ci95_mps) {
        (Some(w), [lo, hi]) => {
            let _ = writeln!(
                o,
                "predicted wobble speed {w:.2} m/s, 95 % interval {} to {}",
                speed_text(lo, "unbounded"),
                speed_text(hi, "unbounded (the data cannot bound it)")
            );
        }
        (None, [Some(lo), _]) => {
            let _ = writeln!(
                o,
                "no predicted wobble speed; the data only say it is above {lo:.2} m/s"
            );
        }
        (None, _) => {
            let _ = writeln!(o, "no predicted wobble speed");
        }
    }
    if let Some(why) = &r.open_because {
        let _ = writeln!(o, "interval open above: {why}");
    }
    match r.ride_below_mps {
        Some(v) => {
            let _ = writeln!(
                o,
                "ride below {v:.2} m/s (the lower bound less {:.0} %)",
                100.0 * r.ride_margin
            );
        }
        None => {
            let _ = writeln!(
                o,
                "no riding limit: the kicks bound no wobble speed from below; stay at speeds \
                 already kicked"
            );
        }
    }
    if let Some(v) = r.next_pass_max_mps {
        let _ = writeln!(o, "next pass at most {v:.2} m/s");
    }
    if let Some([lo, hi]) = r.speed_range_mps {
        let _ = writeln!(o, "kicks used between {lo:.2} and {hi:.2} m/s");
    }
    if let Some(c) = &r.coefficients {
        let terms = ["", " * speed", " * speed^2"];
        let sum: Vec<String> = c
            .iter()
            .zip(terms)
            .map(|(c, t)| format!("{c:+.4}{t}"))
            .collect();
        let _ = writeln!(o, "sigma = {} (1/s, speed in m/s)", sum.join(" "));
    }
    if let Some(s2) = r.unit_variance {
        let _ = writeln!(
            o,
            "scatter about the trend: {:.2} times the kicks' stated SD",
            s2.sqrt()
        );
    }
    if let Some(tau) = r.between_kick_sd_per_s {
        let _ = writeln!(o, "between-kick SD of the true damping: {tau:.3} 1/s");
    }
    for w in &r.warnings {
        let _ = writeln!(o, "warning: {w}");
    }
    let _ = writeln!(o, "method: {}", r.method);
    if let Some(m) = &r.model {
        let _ = writeln!(
            o,
            "model ({}): wobble speed {}, 95 % interval {} to {}",
            escape_controls(&m.params_file),
            speed_text(
                m.wobble_speed_mps,
                "none (the fitted model's wobble never turns unstable)"
            ),
            speed_text(m.ci95_mps[0], "unbounded"),
            speed_text(m.ci95_mps[1], "unbounded")
        );
        for p in &m.params {
            let _ = writeln!(
                o,
                "  {} = {:.4} +/- {:.4} {} (95 %)",
                escape_controls(&p.key),
                p.value,
                p.ci95,
                escape_controls(&p.unit)
            );
        }
        let _ = writeln!(o, "  method: {}", escape_controls(&m.method));
    }
    o
}
