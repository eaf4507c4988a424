//! The kicks of one log as a campaign uses them: the card's kick records
//! (tag 0x83, measured on board) where the log has them, the host's
//! measurement from the steering signal ([`super::kicks`]) otherwise, and
//! for a kick both saw, the host's re-measurement of it (the more accurate
//! of the two on the simulated campaigns, `host-tools/docs/kick-testing.md`)
//! with the card's record kept beside it.
//!
//! Each kick says where its values come from ([`Source`]). The card's
//! stated standard error is the on-board fit's, which treats its
//! overlapping demodulation segments as independent and cannot see the
//! road's share; the host states [`card_sd`] of it (see there).
//!
//! `margin` reads a log's kicks as it streams by ([`load_campaign_kicks`]);
//! [`campaign_kicks`] gives the same for a run held in memory, and
//! [`combine`] pairs the host's kicks with the card's records for both and
//! for the episodes that are kicks ([`super::kick_episodes`]).

use std::path::Path;

use serde::Serialize;
use wobble_core::format::KickRingDown;

use super::kicks::{find_kicks, Kick, KickSearch};
use super::run::{read_rows, stream_rows, Run};
use super::Ride;
use crate::cmd::detect::wheel_circumference_m;
use crate::summary::{Summary, SummaryBuilder};
use crate::CliError;

/// A card record and a host measurement within this of each other are the
/// same kick, s (the card dates a kick from its impulse, the host from its
/// ring's rise; they differ by a few frames).
pub const MATCH_S: f64 = 0.5;

/// The host's stated uncertainty of a card record's sigma is its stated
/// standard error scaled by this... The board's margin warning weighs its
/// kicks by the same (`wobble_core::detector::Kick::sigma_sd_per_s`), so the
/// calibration and its reasons live in the core
/// ([`wobble_core::detector::SIGMA_SE_FACTOR`]).
pub const CARD_SE_FACTOR: f64 = wobble_core::detector::SIGMA_SE_FACTOR;
/// ... with this (1/s) added in quadrature.
pub const CARD_SD_FLOOR_PER_S: f64 = wobble_core::detector::SIGMA_SD_FLOOR_PER_S;

/// The standard uncertainty of a card record's sigma from its stated
/// standard error `se`: `sqrt((CARD_SE_FACTOR se)^2 +
/// CARD_SD_FLOOR_PER_S^2)`, in `f64` (the board's is `f32`). Calibrated as
/// the host's own ([`super::kicks::stated_sd`]): on seeds 100-111 (844
/// kicks the board measured), checked on seeds 200-249: 66.0 % of the
/// errors within one SD and 92.4 % within two; with the record's own
/// error, 43 % within two.
#[must_use]
pub fn card_sd(se: f64) -> f64 {
    (CARD_SE_FACTOR * se).hypot(CARD_SD_FLOOR_PER_S)
}

/// Where a kick's values come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Source {
    /// The card's kick record, as the board measured it.
    Card,
    /// The host's measurement from the steering signal; the log has no
    /// record of this kick.
    Host,
    /// A kick the card recorded, re-measured by the host from the steering
    /// signal: the host's values, the card's record beside them.
    CardHost,
}

impl Source {
    /// The name JSON and the table use.
    #[must_use]
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::Card => "card",
            Self::Host => "host",
            Self::CardHost => "card-host",
        }
    }
}

/// Which measurements a campaign takes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Prefer {
    /// The host's re-measurement where both have a kick, else whichever
    /// has it.
    #[default]
    Best,
    /// Only the card's records (a log without any gives no kicks).
    Card,
    /// Only the host's measurements from the steering signal.
    Host,
}

/// A card record of a kick, in SI units.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CardKick {
    /// Kick time, s since boot.
    pub t_s: f64,
    /// Speed the board measured over the ring, m/s (`None`: unknown).
    pub speed_mps: Option<f64>,
    /// Ring frequency, Hz.
    pub freq_hz: f64,
    /// Growth rate, 1/s.
    pub sigma_per_s: f64,
    /// The standard error of sigma as the card states it, 1/s.
    pub sigma_se_per_s: f64,
    /// Amplitude at the kick, degrees.
    pub amp_deg: f64,
    /// Demodulation segments the board fitted.
    pub segments: u8,
}

impl From<&KickRingDown> for CardKick {
    fn from(k: &KickRingDown) -> Self {
        Self {
            t_s: k.t_us as f64 / 1e6,
            speed_mps: k.speed_mps().map(f64::from),
            freq_hz: f64::from(k.freq_hz()),
            sigma_per_s: f64::from(k.sigma_milli_per_s) / 1000.0,
            sigma_se_per_s: f64::from(k.sigma_se_milli_per_s) / 1000.0,
            amp_deg: f64::from(k.amp_cdeg) / 100.0,
            segments: k.segments,
        }
    }
}

/// One kick of a campaign.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CampaignKick {
    /// Where the values below come from.
    pub source: Source,
    /// Kick time, s since boot.
    pub t_s: f64,
    /// Speed, m/s.
    pub speed_mps: f64,
    /// Ring frequency, Hz.
    pub freq_hz: f64,
    /// Growth rate, 1/s.
    pub sigma_per_s: f64,
    /// Standard uncertainty of sigma as the host states it, 1/s.
    pub sigma_sd_per_s: f64,
    /// Amplitude, degrees.
    pub amp_deg: f64,
    /// The host's fit (absent for a card record alone).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub host: Option<Kick>,
    /// The card's record (absent for a kick only the host found).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub card: Option<CardKick>,
}

impl CampaignKick {
    fn from_host(kick: Kick, card: Option<CardKick>) -> Self {
        Self {
            source: if card.is_some() {
                Source::CardHost
            } else {
                Source::Host
            },
            t_s: kick.t_s,
            speed_mps: kick.speed_mps,
            freq_hz: kick.freq_hz,
            sigma_per_s: kick.sigma_per_s,
            sigma_sd_per_s: kick.sigma_sd_per_s,
            amp_deg: kick.amp_deg,
            host: Some(kick),
            card,
        }
    }

    /// A card record alone; without a recorded speed `speed_after` of
    /// its time stands in. `None` when neither gives a speed.
    fn from_card(card: CardKick, speed_after: impl Fn(f64) -> Option<f64>) -> Option<Self> {
        let speed = card.speed_mps.or_else(|| speed_after(card.t_s))?;
        Some(Self {
            source: Source::Card,
            t_s: card.t_s,
            speed_mps: speed,
            freq_hz: card.freq_hz,
            sigma_per_s: card.sigma_per_s,
            sigma_sd_per_s: card_sd(card.sigma_se_per_s),
            amp_deg: card.amp_deg,
            host: None,
            card: Some(card),
        })
    }
}

/// A card record without a speed takes the mean wheel speed over this long
/// after it, s.
pub const CARD_SPEED_SPAN_S: f64 = 2.0;

/// The mean wheel speed over `[t, t + CARD_SPEED_SPAN_S]` for each of some
/// times `t`, gathered from frames in file order (a log's or a run's).
pub struct SpeedsAfter {
    /// Each time, the sum of the speeds in its span and their count, in
    /// time order.
    spans: Vec<(f64, f64, usize)>,
}

impl SpeedsAfter {
    /// The speeds after the card records of `records` that have none.
    #[must_use]
    pub fn for_records(records: &[KickRingDown]) -> Self {
        let mut times: Vec<f64> = records
            .iter()
            .map(CardKick::from)
            .filter(|c| c.speed_mps.is_none())
            .map(|c| c.t_s)
            .collect();
        times.sort_by(f64::total_cmp);
        times.dedup();
        Self {
            spans: times.into_iter().map(|t| (t, 0.0, 0)).collect(),
        }
    }

    /// Whether no record needs a speed (then no frame need be pushed).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.spans.is_empty()
    }

    /// Takes a frame at `t_s` with wheel speed `speed_mps`.
    /// Adds the frame at `t_s` with wheel speed `speed_mps`.
    pub fn push(&mut self, t_s: f64, speed_mps: f64) {
        // Every span holding `t_s` starts at or before it and less than a
        // span (and rounding) before it.
        let first = self
            .spans
            .partition_point(|s| s.0 < t_s - CARD_SPEED_SPAN_S - 1e-6);
        for span in self.spans[first..].iter_mut().take_while(|s| s.0 <= t_s) {
            if (span.0..=span.0 + CARD_SPEED_SPAN_S).contains(&t_s) {
                span.1 += speed_mps;
                span.2 += 1;
            }
        }
    }

    /// The mean speed over the span after `t_s` (`None`: no frame in it).
    /// The mean speed after the record at `t_s`, if frames followed it.
    #[must_use]
    pub fn after(&self, t_s: f64) -> Option<f64> {
        let i = self.spans.partition_point(|s| s.0 < t_s);
        let &(from, sum, n) = self.spans.get(i)?;
        (from == t_s && n > 0).then(|| sum / n as f64)
    }
}

/// The kicks of `run` (in time order), taken as `prefer` says. A card
/// record without a speed takes the run's mean wheel speed over the
/// [`CARD_SPEED_SPAN_S`] after it.
#[must_use]
pub fn campaign_kicks(run: &Run, wheel_circumference_m: f64, prefer: Prefer) -> Vec<CampaignKick> {
    let host = if prefer == Prefer::Card {
        Vec::new()
    } else {
        find_kicks(run, wheel_circumference_m)
    };
    let mut speeds = SpeedsAfter::for_records(&run.summary.kick_records);
    if !speeds.is_empty() {
        for (&t, &v) in run.t_s.iter().zip(&run.speed_mps) {
            speeds.push(t, v);
        }
    }
    combine(host, &run.summary.kick_records, prefer, |t| speeds.after(t))
}

/// The kicks of the log at `path` (in time order), taken as `prefer` says,
/// and what `wobblog info` says about the log: what [`campaign_kicks`]
/// gives for the log loaded whole, read in memory that does not grow with
/// the log. The host searches its frames as they stream by
/// ([`KickSearch`], on the wheel its header's config gives); the mean
/// speeds after card records without one take a second pass, made only
/// when there are such records.
///
/// # Errors
/// The log cannot be read or has no frames, or its config is refused.
pub fn load_campaign_kicks(
    path: &Path,
    prefer: Prefer,
) -> Result<(Summary, Vec<CampaignKick>), CliError> {
    let make = |told: &SummaryBuilder| {
        let wheel_m = wheel_circumference_m(told.config()).ok();
        wheel_m
            .filter(|_| prefer != Prefer::Card)
            .map(|w| KickSearch::new(told.frame_rate_hz(), w))
    };
    let (summary, search) = stream_rows(path, make, |search, row| {
        if let Some(search) = search {
            search.push(row.t_s, row.steer_deg, row.speed_mps);
        }
    })?;
    // A config the host refuses is an error, as for every kick command.
    wheel_circumference_m(&summary.config)?;
    let host = search.map(KickSearch::finish).unwrap_or_default();
    let mut speeds = SpeedsAfter::for_records(&summary.kick_records);
    if !speeds.is_empty() {
        read_rows(path, |_| {}, |row| speeds.push(row.t_s, row.speed_mps))?;
    }
    let kicks = combine(host, &summary.kick_records, prefer, |t| speeds.after(t));
    Ok((summary, kicks))
}

/// The kicks of the log `ride` analysed (in time order), taken as
/// `prefer` says: what [`load_campaign_kicks`] gives for the same log
/// without reading it again, the host's kicks being those the analysis
/// measured. `speeds` holds the log's frames' speeds after its card
/// records that have none ([`SpeedsAfter::for_records`]).
///
/// # Errors
/// The log's config is refused, as for every kick command.
pub fn ride_campaign_kicks(
    ride: &Ride,
    prefer: Prefer,
    speeds: &SpeedsAfter,
) -> Result<Vec<CampaignKick>, CliError> {
    wheel_circumference_m(&ride.summary.config)?;
    let host = match (&ride.host_kicks, prefer) {
        (Some(kicks), Prefer::Host | Prefer::Best) => kicks.clone(),
        _ => Vec::new(),
    };
    Ok(combine(host, &ride.summary.kick_records, prefer, |t| {
        speeds.after(t)
    }))
}

/// The kicks of a log (in time order) from the host's measurements `host`
/// (from [`find_kicks`] or a [`super::kicks::KickSearch`]) and the card's
/// `records`, taken as `prefer` says: where both saw a kick (within
/// [`MATCH_S`]), the host's values with the card's record beside them. A
/// card record without a speed takes `speed_after` of its time, and is
/// left out when that gives none.
#[must_use]
pub fn combine(
    host: Vec<Kick>,
    records: &[KickRingDown],
    prefer: Prefer,
    speed_after: impl Fn(f64) -> Option<f64>,
) -> Vec<CampaignKick> {
    let cards: Vec<CardKick> = records.iter().map(CardKick::from).collect();
    let mut out: Vec<CampaignKick> = match prefer {
        Prefer::Host => host
            .into_iter()
            .map(|k| CampaignKick::from_host(k, None))
            .collect(),
        Prefer::Card => cards
            .into_iter()
            .filter_map(|c| CampaignKick::from_card(c, &speed_after))
            .collect(),
        Prefer::Best => {
            let mut taken = vec![false; cards.len()];
            let mut out: Vec<CampaignKick> = host
                .into_iter()
                .map(|k| {
                    let nearest = (0..cards.len())
                        .filter(|&i| !taken[i] && (cards[i].t_s - k.t_s).abs() <= MATCH_S)
                        .min_by(|&a, &b| {
                            (cards[a].t_s - k.t_s)
                                .abs()
                                .total_cmp(&(cards[b].t_s - k.t_s).abs())
                        });
                    let card = nearest.map(|i| {
                        taken[i] = true;
                        cards[i].clone()
                    });
                    CampaignKick::from_host(k, card)
                })
                .collect();
            out.extend(
                cards
                    .into_iter()
                    .zip(taken)
                    .filter(|(_, t)| !t)
                    .filter_map(|(c, _)| CampaignKick::from_card(c, &speed_after)),
            );
            out
        }
    };
    out.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
    out
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::f64::consts::TAU;

    /// A 10 s run at 3 m/s with one knock at 3 s ringing at 7 Hz, decaying
    /// at 1 1/s from 1.5 degrees, over a little deterministic noise.
    fn run_with_a_ring(records: Vec<KickRingDown>) -> Run {
        let t_s: Vec<f64> = (0..1000).map(|i| f64::from(i) / 100.0).collect();
        let steer_deg = t_s
            .iter()
            .enumerate()
            .map(|(i, &t)| {
                let tau = t - 3.0;
                let ring = if tau >= 0.0 {
                    1.5 * (-tau).exp() * (TAU * 7.0 * tau).sin()
                } else {
                    0.0
                };
                ring + 0.01 * ((i * 7919) % 13) as f64 / 13.0
            })
            .collect();
        let mut run = Run {
            speed_mps: vec![3.0; t_s.len()],
            t_s,
            steer_deg,
            ..Run::default()
        };
        run.summary.kick_records = records;
        run
    }

    /// A card record of a kick at `t_s`: 6.9 Hz, sigma -1.1 +- 0.05.
    pub(crate) fn record(t_s: f64, speed_mm_s: Option<u16>) -> KickRingDown {
        KickRingDown {
            t_us: (t_s * 1e6) as u64,
            speed_mm_s,
            freq_chz: 690,
            sigma_milli_per_s: -1100,
            sigma_se_milli_per_s: 50,
            amp_cdeg: 140,
            segments: 9,
        }
    }

    #[test]
    fn a_kick_both_saw_is_the_hosts_with_the_card_beside_it() {
        let run = run_with_a_ring(vec![record(2.95, Some(3010))]);
        let kicks = campaign_kicks(&run, 2.2, Prefer::Best);
        assert_eq!(kicks.len(), 1, "{kicks:?}");
        let k = &kicks[0];
        assert_eq!(k.source, Source::CardHost);
        let host = k.host.as_ref().unwrap();
        assert_eq!((k.sigma_per_s, k.freq_hz), (host.sigma_per_s, host.freq_hz));
        assert!((k.sigma_per_s + 1.0).abs() < 0.1, "{k:?}");
        assert_eq!(k.card.as_ref().unwrap().sigma_per_s, -1.1);
    }

    #[test]
    fn a_card_record_alone_is_used_with_its_error_corrected() {
        // The host finds the ring at 3 s; the card also has a kick at 7 s
        // (too small for the host), and one at 8.5 s without a speed.
        let run = run_with_a_ring(vec![record(7.0, Some(2500)), record(8.5, None)]);
        let kicks = campaign_kicks(&run, 2.2, Prefer::Best);
        let sources: Vec<Source> = kicks.iter().map(|k| k.source).collect();
        assert_eq!(sources, [Source::Host, Source::Card, Source::Card]);
        let card = &kicks[1];
        assert_eq!(card.speed_mps, 2.5);
        assert!((card.sigma_sd_per_s - card_sd(0.05)).abs() < 1e-12);
        assert!(card.sigma_sd_per_s > 0.05 * CARD_SE_FACTOR);
        assert!(card.host.is_none());
        // The run's own speed where the record has none.
        assert!((kicks[2].speed_mps - 3.0).abs() < 1e-12);
    }

    #[test]
    fn card_or_host_alone_when_asked() {
        let run = run_with_a_ring(vec![record(2.95, Some(3010)), record(7.0, Some(2500))]);
        let card = campaign_kicks(&run, 2.2, Prefer::Card);
        assert_eq!(card.len(), 2);
        assert!(card.iter().all(|k| k.source == Source::Card));
        assert_eq!(card[0].sigma_per_s, -1.1);
        let host = campaign_kicks(&run, 2.2, Prefer::Host);
        assert_eq!(host.len(), 1);
        assert_eq!(host[0].source, Source::Host);
        assert!(host[0].card.is_none());
        // No records: the host's kicks, whatever is preferred but the card.
        let plain = run_with_a_ring(Vec::new());
        assert_eq!(campaign_kicks(&plain, 2.2, Prefer::Best), host);
        assert!(campaign_kicks(&plain, 2.2, Prefer::Card).is_empty());
    }

    #[test]
    fn a_host_kick_pairs_with_the_nearest_record() {
        let host = Kick {
            t_s: 3.0,
            speed_mps: 3.0,
            freq_hz: 7.0,
            sigma_per_s: -1.0,
            sigma_sd_per_s: 0.03,
            sigma_se_fit_per_s: 0.01,
            amp_deg: 1.0,
            fit_s: [3.5, 6.0],
            residual_rel: 0.1,
        };
        // Both within MATCH_S, the nearer after the kick or before it, and
        // first or second in the log.
        for (near, far) in [(3.1, 2.6), (2.9, 3.4)] {
            for (first, second) in [(near, far), (far, near)] {
                let records = [record(first, Some(3000)), record(second, Some(3000))];
                let kicks = combine(vec![host.clone()], &records, Prefer::Best, |_| None);
                let paired: Vec<f64> = kicks
                    .iter()
                    .filter(|k| k.source == Source::CardHost)
                    .map(|k| k.card.as_ref().unwrap().t_s)
                    .collect();
                assert_eq!(paired, [near], "{kicks:?}");
                assert_eq!(kicks.len(), 2);
            }
        }
    }
}
