//! Scores the on-board detector against the corpus's ground truth.
//!
//! - **Latency** of an episode: time of its first `alert_on` minus the time
//!   the true envelope reached 0.5 degrees (negative: the alert came sooner).
//! - **Frequency error**: |frequency reported at `alert_on` - true frequency|.
//! - **False alert**: an `alert_on` outside every episode's window, which
//!   runs from the envelope reaching 0.2 degrees to 1 s after the episode's
//!   end (envelope back below 0.25 degrees).
//!
//! The replay is the same thing `wobblog detect` does: every row goes through
//! [`Detector::push`] with its speed, and an event is stamped with the time of
//! the row that caused it.

use std::fmt::Write as _;

use wobble_core::config::Config;
use wobble_core::detector::{AlertEvent, ConfigError, Estimate};

use crate::corpus::{Fixture, Row};

/// The goals the issue sets (tests assert them; the table reports them).
pub mod goals {
    /// Median alert latency, seconds.
    pub const MEDIAN_LATENCY_S: f64 = 0.35;
    /// Worst alert latency, seconds.
    pub const WORST_LATENCY_S: f64 = 0.6;
    /// Frequency error at alert, Hz.
    pub const FREQ_ERROR_HZ: f64 = 0.25;
    /// Non-wobble riding the corpus must hold, minutes.
    pub const MIN_NON_WOBBLE_MIN: f64 = 30.0;
}

/// Start of an episode's window: the envelope reaching this, degrees.
const WINDOW_START_DEG: f64 = 0.2;
/// End of an episode's window after the episode's end, seconds.
const WINDOW_TAIL_S: f64 = 1.0;

/// An alert change at a time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlertChange {
    /// Time of the row that caused it, seconds.
    pub t_s: f64,
    /// What changed.
    pub event: AlertEvent,
}

/// Header of the per-hop trace that `trace_line` writes.
pub const TRACE_HEADER: &str =
    "t_s,amp_deg,freq_hz,in_band,growth_ratio,trend_per_s,holdoff,harmonic,alert";

/// One CSV line of the detector's state at `t_s` (see [`TRACE_HEADER`]),
/// for looking into a single ride with `detector-metrics --trace`.
#[must_use]
pub fn trace_line(t_s: f64, e: &Estimate, alert: bool) -> String {
    format!(
        "{t_s:.2},{:.3},{:.2},{},{:.3},{:.3},{},{},{}",
        e.amp_deg,
        e.freq_hz,
        u8::from(e.in_band),
        e.growth_ratio,
        e.trend_per_s,
        u8::from(e.impulse_holdoff),
        u8::from(e.at_wheel_harmonic),
        u8::from(alert)
    )
}

/// Replays `rows` through a fresh detector as `config` sets it up (its
/// detector settings on its wheel), giving it the speed column if
/// `use_speed`; `trace`, if given, receives every analysis (time, estimate,
/// alert state).
///
/// # Errors
/// When `config` is invalid.
pub fn replay(
    rows: &[Row],
    config: &Config,
    use_speed: bool,
    mut trace: Option<&mut dyn FnMut(f64, Estimate, bool)>,
) -> Result<Vec<AlertChange>, ConfigError> {
    let mut det = config.detector()?;
    let mut out = Vec::new();
    for r in rows {
        let speed = use_speed.then_some(r.speed_mps);
        if let Some(event) = det.push(r.steer_deg, speed) {
            out.push(AlertChange { t_s: r.t_s, event });
        }
        if let Some(f) = trace.as_mut() {
            if det.analysed() {
                f(r.t_s, det.estimate(), det.alert_active());
            }
        }
    }
    Ok(out)
}

/// How the detector did on one episode.
#[derive(Clone, Debug, PartialEq)]
pub struct EpisodeScore {
    /// Fixture name.
    pub fixture: String,
    /// True wobble frequency, Hz.
    pub freq_hz: f64,
    /// True growth rate, 1/s.
    pub growth_per_s: f64,
    /// Speed, m/s.
    pub speed_mps: f64,
    /// When the envelope reached 0.5 degrees.
    pub t_ref_s: f64,
    /// First alert in the episode's window.
    pub alert_s: Option<f64>,
    /// Frequency reported at the alert.
    pub alert_freq_hz: Option<f64>,
    /// Amplitude reported at the alert.
    pub alert_amp_deg: Option<f64>,
    /// First `alert_off` after the alert.
    pub off_s: Option<f64>,
    /// Episode end (envelope below 0.25 degrees).
    pub end_s: f64,
    /// Further `alert_on`s within the same window (chatter).
    pub extra_alerts: usize,
}

impl EpisodeScore {
    /// Alert latency, seconds.
    #[must_use]
    pub fn latency_s(&self) -> Option<f64> {
        self.alert_s.map(|t| t - self.t_ref_s)
    }

    /// Frequency error at the alert, Hz.
    #[must_use]
    pub fn freq_error_hz(&self) -> Option<f64> {
        self.alert_freq_hz.map(|f| (f - self.freq_hz).abs())
    }
}

/// How the detector did on one fixture.
#[derive(Clone, Debug, PartialEq)]
pub struct FixtureScore {
    /// Fixture name.
    pub name: String,
    /// Whether the CSV is committed.
    pub committed: bool,
    /// Length, seconds.
    pub duration_s: f64,
    /// Number of wobble episodes.
    pub episodes: usize,
    /// Number of non-wobble events by kind: kicks, potholes, kerbs, corners.
    pub events: [usize; 4],
    /// Every `alert_on`.
    pub alerts: usize,
    /// Times of the `alert_on`s outside every episode window.
    pub false_alerts: Vec<f64>,
}

/// The corpus benchmark's result.
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// Per episode.
    pub episodes: Vec<EpisodeScore>,
    /// Per fixture.
    pub fixtures: Vec<FixtureScore>,
    /// The configuration measured.
    pub config: Config,
    /// Whether the detector was given the speed.
    pub use_speed: bool,
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

impl Report {
    /// Latencies of the detected episodes.
    #[must_use]
    pub fn latencies_s(&self) -> Vec<f64> {
        self.episodes
            .iter()
            .filter_map(EpisodeScore::latency_s)
            .collect()
    }

    /// Median latency over detected episodes.
    #[must_use]
    pub fn median_latency_s(&self) -> Option<f64> {
        median(self.latencies_s())
    }

    /// Worst latency over detected episodes.
    #[must_use]
    pub fn worst_latency_s(&self) -> Option<f64> {
        self.latencies_s().into_iter().reduce(f64::max)
    }

    /// Every way the detector missed the goals with this report: an episode
    /// without an alert or with chatter, the median or worst latency, the
    /// frequency error (empty: all goals met).
    #[must_use]
    pub fn goal_failures(&self) -> Vec<String> {
        let mut out = Vec::new();
        for e in &self.episodes {
            if e.alert_s.is_none() {
                out.push(format!("{}: no alert", e.fixture));
            }
            if e.extra_alerts > 0 {
                out.push(format!("{}: {} extra alerts", e.fixture, e.extra_alerts));
            }
        }
        let over = |what: &str, v: Option<f64>, goal: f64| {
            v.filter(|&v| v > goal)
                .map(|v| format!("{what} {v:.3} over {goal}"))
        };
        out.extend(over(
            "median latency (s)",
            self.median_latency_s(),
            goals::MEDIAN_LATENCY_S,
        ));
        out.extend(over(
            "worst latency (s)",
            self.worst_latency_s(),
            goals::WORST_LATENCY_S,
        ));
        out.extend(over(
            "frequency error (Hz)",
            self.max_freq_error_hz(),
            goals::FREQ_ERROR_HZ,
        ));
        out
    }

    /// Largest frequency error at alert.
    #[must_use]
    pub fn max_freq_error_hz(&self) -> Option<f64> {
        self.episodes
            .iter()
            .filter_map(EpisodeScore::freq_error_hz)
            .reduce(f64::max)
    }

    /// Episodes without an alert.
    #[must_use]
    pub fn missed(&self) -> usize {
        self.episodes.iter().filter(|e| e.alert_s.is_none()).count()
    }

    /// Seconds of fixtures without any wobble episode.
    #[must_use]
    pub fn non_wobble_s(&self) -> f64 {
        self.fixtures
            .iter()
            .filter(|f| f.episodes == 0)
            .map(|f| f.duration_s)
            .sum()
    }

    /// False alerts in all fixtures (wobble fixtures outside their windows
    /// included).
    #[must_use]
    pub fn false_alerts(&self) -> usize {
        self.fixtures.iter().map(|f| f.false_alerts.len()).sum()
    }

    /// False alerts in non-wobble fixtures per hour of them.
    #[must_use]
    pub fn false_alerts_per_hour(&self) -> f64 {
        let n: usize = self
            .fixtures
            .iter()
            .filter(|f| f.episodes == 0)
            .map(|f| f.false_alerts.len())
            .sum();
        n as f64 / (self.non_wobble_s() / 3600.0)
    }

    /// `alert_on`s in non-wobble fixtures.
    #[must_use]
    pub fn non_wobble_false_alerts(&self) -> usize {
        self.fixtures
            .iter()
            .filter(|f| f.episodes == 0)
            .map(|f| f.false_alerts.len())
            .sum()
    }

    /// `alert_on`s in wobble fixtures outside their episodes.
    #[must_use]
    pub fn wobble_fixture_false_alerts(&self) -> usize {
        self.fixtures
            .iter()
            .filter(|f| f.episodes > 0)
            .map(|f| f.false_alerts.len())
            .sum()
    }
}

fn opt(v: Option<f64>, prec: usize) -> String {
    v.map_or("-".to_owned(), |x| format!("{x:.prec$}"))
}

/// Episodes the detector found, of all: `found / all`.
fn detected(r: &Report) -> String {
    format!("{} / {}", r.episodes.len() - r.missed(), r.episodes.len())
}

/// The metrics file (`hil-tests/fixtures/corpus/METRICS.md`): the detector
/// with the speed (as on the bike, where the goals apply) and without it (a
/// CSV without `speed_mps`).
#[must_use]
pub fn markdown(with_speed: &Report, without_speed: &Report) -> String {
    let mut s = String::new();
    let w = with_speed;
    let n = without_speed;
    let _ = writeln!(s, "# Wobble detector metrics\n");
    let _ = writeln!(
        s,
        "Written by `cargo run -p wobble-hil --release --bin detector-metrics`; \
         `hil-tests/tests/detector_corpus.rs` asserts the goals and that this file is current. \
         Detector: the firmware's complete default configuration, `Config::default()` \
         (`DetectorConfig::default()` on the default wheel, {:.3} m). Corpus: `hil-tests/fixtures/corpus/manifest.json`. \
         Definitions: `hil-tests/src/metrics.rs`.\n",
        w.config.wheel.circumference_m
    );
    let _ = writeln!(s, "## Summary\n");
    let _ = writeln!(
        s,
        "| metric | goal | with speed (firmware) | steering only |\n|---|---|---|---|"
    );
    let _ = writeln!(
        s,
        "| episodes detected | all | {} | {} |",
        detected(w),
        detected(n)
    );
    let _ = writeln!(
        s,
        "| median alert latency (from envelope = 0.5 deg) | <= {} s | {} s | {} s |",
        goals::MEDIAN_LATENCY_S,
        opt(w.median_latency_s(), 2),
        opt(n.median_latency_s(), 2)
    );
    let _ = writeln!(
        s,
        "| worst alert latency | <= {} s | {} s | {} s |",
        goals::WORST_LATENCY_S,
        opt(w.worst_latency_s(), 2),
        opt(n.worst_latency_s(), 2)
    );
    let _ = writeln!(
        s,
        "| worst frequency error at alert | <= {} Hz | {} Hz | {} Hz |",
        goals::FREQ_ERROR_HZ,
        opt(w.max_freq_error_hz(), 3),
        opt(n.max_freq_error_hz(), 3)
    );
    let _ = writeln!(
        s,
        "| false alerts on non-wobble rides ({:.1} min) | 0 in >= {} min | {} ({:.1} per hour) | {} ({:.1} per hour) |",
        w.non_wobble_s() / 60.0,
        goals::MIN_NON_WOBBLE_MIN,
        w.non_wobble_false_alerts(),
        w.false_alerts_per_hour(),
        n.non_wobble_false_alerts(),
        n.false_alerts_per_hour()
    );
    let _ = writeln!(
        s,
        "| false alerts in wobble fixtures, outside the episodes | 0 | {} | {} |",
        w.wobble_fixture_false_alerts(),
        n.wobble_fixture_false_alerts()
    );
    if let Ok(c) = w.config.detector.cost() {
        let _ = writeln!(
            s,
            "\nArithmetic per sample (analytical, `DetectorConfig::cost`): average {} mul + {} add, \
             worst (a sample that ends a hop, fires the alert and reports a kick) {} mul + {} add; \
             {} Goertzel steps per hop. \
             Add the harmonic canceller when speed is known: at most {} mul + {} add per sample. \
             See `firmware/docs/detector.md` for cycles on the Cortex-M4F.",
            c.average.mul, c.average.add, c.worst.mul, c.worst.add, c.goertzel_steps_per_hop,
            c.canceller.mul, c.canceller.add
        );
    }
    let _ = writeln!(s, "\n## Episodes (with speed)\n");
    let _ = writeln!(
        s,
        "| fixture | f (Hz) | growth (1/s) | speed (m/s) | 0.5 deg at (s) | alert at (s) | \
         latency (s) | f at alert (Hz) | f error (Hz) | amp at alert (deg) | off after end (s) | \
         latency without speed (s) |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (e, e2) in w.episodes.iter().zip(&n.episodes) {
        let _ = writeln!(
            s,
            "| {} | {:.2} | {:.2} | {:.1} | {:.2} | {} | {} | {} | {} | {} | {} | {} |",
            e.fixture,
            e.freq_hz,
            e.growth_per_s,
            e.speed_mps,
            e.t_ref_s,
            opt(e.alert_s, 2),
            opt(e.latency_s(), 2),
            opt(e.alert_freq_hz, 2),
            opt(e.freq_error_hz(), 3),
            opt(e.alert_amp_deg, 2),
            opt(e.off_s.map(|t| t - e.end_s), 2),
            opt(e2.latency_s(), 2),
        );
    }
    let _ = writeln!(s, "\n## Fixtures\n");
    let _ = writeln!(
        s,
        "| fixture | committed | duration (min) | episodes | kicks | potholes | kerbs | corners | \
         alerts | false alerts | false alerts without speed |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|");
    for (f, f2) in w.fixtures.iter().zip(&n.fixtures) {
        let _ = writeln!(
            s,
            "| {} | {} | {:.1} | {} | {} | {} | {} | {} | {} | {} | {} |",
            f.name,
            if f.committed { "yes" } else { "generated" },
            f.duration_s / 60.0,
            f.episodes,
            f.events[0],
            f.events[1],
            f.events[2],
            f.events[3],
            f.alerts,
            f.false_alerts.len(),
            f2.false_alerts.len()
        );
    }
    s
}

/// The section of the metrics file on the simulated family
/// (`hil-tests/fixtures/corpus/simulated/`, rides simulated from the
/// bicycle model), the detector given the speed as on the bike.
#[must_use]
pub fn simulated_markdown(r: &Report) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "\n## Simulated family (bicycle model)\n\n\
         Rides simulated in time from the linear wobble model of the test bicycle \
         (`hil-tests/src/corpus/simulated/`; synthetic, but steering, roll rate, yaw rate, lateral \
         acceleration and the wheel's edges are one motion); truth from the model's wobble \
         eigenvalue and modal amplitude. Same detector, same goals, no retuning; \
         `hil-tests/tests/simulated_corpus.rs` asserts them.\n"
    );
    let _ = writeln!(
        s,
        "| metric | goal | with speed (firmware) |\n|---|---|---|"
    );
    let _ = writeln!(s, "| episodes detected | all | {} |", detected(r));
    let _ = writeln!(
        s,
        "| median / worst alert latency | <= {} / {} s | {} / {} s |",
        goals::MEDIAN_LATENCY_S,
        goals::WORST_LATENCY_S,
        opt(r.median_latency_s(), 2),
        opt(r.worst_latency_s(), 2)
    );
    let _ = writeln!(
        s,
        "| worst frequency error at alert | <= {} Hz | {} Hz |",
        goals::FREQ_ERROR_HZ,
        opt(r.max_freq_error_hz(), 3)
    );
    let _ = writeln!(
        s,
        "| false alerts on non-wobble rides ({:.1} min) / in wobble rides | 0 / 0 | {} / {} |",
        r.non_wobble_s() / 60.0,
        r.non_wobble_false_alerts(),
        r.wobble_fixture_false_alerts()
    );
    let _ = writeln!(
        s,
        "\n| ride | f (Hz) | growth (1/s) | speed (m/s) | 0.5 deg at (s) | alert at (s) | latency (s) | f error (Hz) |\n|---|---|---|---|---|---|---|---|"
    );
    for e in &r.episodes {
        let _ = writeln!(
            s,
            "| {} | {:.2} | {:.2} | {:.1} | {:.2} | {} | {} | {} |",
            e.fixture,
            e.freq_hz,
            e.growth_per_s,
            e.speed_mps,
            e.t_ref_s,
            opt(e.alert_s, 2),
            opt(e.latency_s(), 2),
            opt(e.freq_error_hz(), 3)
        );
    }
    s
}

/// Runs the detector as `config` sets it up over every fixture and scores
/// it; the detector gets the speed column if `use_speed` (as on the bike).
///
/// # Errors
/// An invalid `config`, or a fixture whose CSV does not parse.
pub fn evaluate(fixtures: &[Fixture], config: &Config, use_speed: bool) -> Result<Report, String> {
    let mut episodes = Vec::new();
    let mut scores = Vec::new();
    for fx in fixtures {
        let rows = fx.rows()?;
        let changes = replay(&rows, config, use_speed, None).map_err(|e| e.to_string())?;
        let truth = &fx.truth;
        let windows: Vec<(f64, f64)> = truth
            .episodes
            .iter()
            .map(|e| {
                let start = e.onset_s + (WINDOW_START_DEG / e.onset_amp_deg).ln() / e.growth_per_s;
                (start, e.end_s + WINDOW_TAIL_S)
            })
            .collect();
        for (e, &(w0, w1)) in truth.episodes.iter().zip(&windows) {
            let ons: Vec<(usize, &AlertChange)> = changes
                .iter()
                .enumerate()
                .filter(|(_, c)| {
                    matches!(c.event, AlertEvent::On { .. }) && c.t_s >= w0 && c.t_s <= w1
                })
                .collect();
            let first = ons.first();
            let (freq, amp) = match first.map(|(_, c)| c.event) {
                Some(AlertEvent::On { freq_hz, amp_deg }) => {
                    (Some(f64::from(freq_hz)), Some(f64::from(amp_deg)))
                }
                _ => (None, None),
            };
            let off_s = first.and_then(|&(i, _)| {
                changes[i..]
                    .iter()
                    .find(|c| c.event == AlertEvent::Off)
                    .map(|c| c.t_s)
            });
            episodes.push(EpisodeScore {
                fixture: truth.name.clone(),
                freq_hz: e.freq_hz,
                growth_per_s: e.growth_per_s,
                speed_mps: e.speed_mps,
                t_ref_s: e.t_ref_s,
                alert_s: first.map(|(_, c)| c.t_s),
                alert_freq_hz: freq,
                alert_amp_deg: amp,
                off_s,
                end_s: e.end_s,
                extra_alerts: ons.len().saturating_sub(1),
            });
        }
        let ons: Vec<f64> = changes
            .iter()
            .filter(|c| matches!(c.event, AlertEvent::On { .. }))
            .map(|c| c.t_s)
            .collect();
        let count = |k: &str| truth.events.iter().filter(|e| e.kind == k).count();
        scores.push(FixtureScore {
            name: truth.name.clone(),
            committed: truth.committed,
            duration_s: truth.duration_s,
            episodes: truth.episodes.len(),
            events: [
                count("kick"),
                count("pothole"),
                count("kerb"),
                count("corner"),
            ],
            alerts: ons.len(),
            false_alerts: ons
                .into_iter()
                .filter(|&t| !windows.iter().any(|&(w0, w1)| t >= w0 && t <= w1))
                .collect(),
        });
    }
    Ok(Report {
        episodes,
        fixtures: scores,
        config: *config,
        use_speed,
    })
}

/// The default configuration with `key=value` overrides (comma-separated),
/// for the tuning examples (`examples/sweep.rs`, `examples/stress.rs`): any
/// `CONFIG.TXT` key (`wheel.circumference_m=2.13`), and detector keys also
/// without their `detector.` prefix (`amp_on_deg=0.45`). Read by the
/// firmware's own config parser, so the examples know every key it knows.
///
/// # Errors
/// A line the parser reports (unknown key, bad value, rejected section).
pub fn override_config(spec: &str) -> Result<Config, String> {
    let text: Vec<String> = spec
        .split(',')
        .filter(|s| !s.is_empty())
        .map(|kv| {
            // The key's own dots, not the value's (`amp_on_deg=0.45`).
            let key = kv.split_once('=').map_or(kv, |(k, _)| k);
            if key.contains('.') {
                kv.to_owned()
            } else {
                format!("detector.{kv}")
            }
        })
        .collect();
    let loaded = Config::parse(text.join("\n").as_bytes());
    match loaded.faults.first().first() {
        None => Ok(loaded.config),
        Some(f) => Err(format!(
            "{spec}: `{}` not used (config fault {})",
            text.get(usize::from(f.line).saturating_sub(1))
                .map_or("", String::as_str),
            f.code
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overrides_take_keys_with_and_without_their_section() {
        let c =
            override_config("amp_on_deg=0.45,detector.window_s=0.32,wheel.circumference_m=2.13")
                .expect("known keys");
        assert_eq!(c.detector.amp_on_deg, 0.45);
        assert_eq!(c.detector.window_s, 0.32);
        assert_eq!(c.wheel.circumference_m, 2.13);
        assert!(override_config("no_such_key=1").is_err());
    }
}
