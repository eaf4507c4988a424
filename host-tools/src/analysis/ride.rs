//! What the commands over many logs (`wobble`, `summary`, the model fits
//! and the data set) take from each: its summary, wobble episodes (a kick's
//! with the kick's values, as `margin` has them), the weave's kicks,
//! distance and top speed, found in one pass over the log in bounded
//! memory.
//!
//! The kick search runs ahead of the episode search: a frame reaches the
//! episodes only once every kick that could have struck an episode up to
//! it is known, so that a stable episode that is a kick takes the kick's
//! values instead of being fitted again (its own fits were most of the
//! time a kick campaign's analysis took). The frames in between are held,
//! at most one piece of the kick search ([`super::kicks::PIECE_FRAMES`]).

use std::collections::VecDeque;
use std::path::{Path, PathBuf};

use super::campaign_kicks::MATCH_S;
use super::filter::follows;
use super::kick_episodes::give_kick_values;
use super::kicks::{Kick, KickMode, KickSearch};
use super::run::{log_name, stream_rows};
use super::search::EpisodeSearch;
use super::{Episode, Run};
use crate::cmd::detect::wheel_circumference_m;
use crate::summary::{Summary, SummaryBuilder};
use crate::CliError;

/// One run, analysed.
#[derive(Clone, Debug)]
pub struct Ride {
    /// The log it was read from.
    pub path: PathBuf,
    /// What `wobblog info` says about it.
    pub summary: Summary,
    /// Every wobble episode, in time order; those that are kicks with the
    /// kick's values as `wobblog margin` takes them
    /// ([`super::kick_episodes`]).
    pub episodes: Vec<Episode>,
    /// Wheel distance over the frames present (trapezoids within each
    /// stretch without a gap), m.
    pub distance_m: f64,
    /// Highest wheel speed, m/s.
    pub max_speed_mps: f64,
    /// The kicks the host measured, as `wobblog margin` finds them
    /// (`None` when the log's config gives no wheel).
    pub host_kicks: Option<Vec<Kick>>,
    /// The weave's kicks, found in the roll rate as `wobblog margin --mode
    /// weave` finds them, in time order.
    pub weave_kicks: Vec<Kick>,
}

impl Ride {
    /// Reads and analyses the log at `path`, streaming its frames.
    pub fn load(path: &Path) -> Result<Self, CliError> {
        let make = |told: &SummaryBuilder| RideAnalysis::new(told.frame_rate_hz(), told.config());
        let (summary, analyser) = stream_rows(path, make, |a, row| {
            a.push(row.t_s, row.steer_deg, row.speed_mps, row.gyro_dps[0]);
        })?;
        Ok(analyser.finish(path, summary))
    }

    /// Analyses a run held in memory: the same analysis as [`Self::load`].
    #[must_use]
    pub fn of(run: &Run) -> Self {
        let mut a = RideAnalysis::new(run.sample_rate_hz(), &run.summary.config);
        for i in 0..run.len() {
            a.push(
                run.t_s[i],
                run.steer_deg[i],
                run.speed_mps[i],
                run.gyro_dps[i][0],
            );
        }
        a.finish(&run.path, run.summary.clone())
    }

    /// Every episode, the weave's kicks as episodes among the wobble's, in
    /// time order: what `wobblog wobble` and the data set list.
    #[must_use]
    pub fn all_episodes(&self) -> Vec<Episode> {
        let mut all = self.episodes.clone();
        all.extend(self.weave_kicks.iter().map(Episode::of_weave_kick));
        all.sort_by(|a, b| a.onset_s.total_cmp(&b.onset_s));
        all
    }

    /// The run's name for reports: the file name.
    #[must_use]
    pub fn name(&self) -> String {
        log_name(&self.path)
    }
}

/// The analysis of a stream of frames: what [`Ride::load`] runs, for a
/// command that reads the frames itself (the plot draws them in the same
/// pass).
pub struct RideAnalysis {
    period_s: f64,
    search: EpisodeSearch,
    /// The kicks, as `wobblog margin` finds them (`None` when the log's
    /// config gives no wheel: margin then takes no kick from the log).
    kicks: Option<KickSearch>,
    /// How many of the kicks found the episode search has been given.
    kicks_given: usize,
    /// The weave's kicks, in the roll rate.
    weave: KickSearch,
    /// Frames (time, steering, speed) the kick search has seen and the
    /// episode search not yet.
    waiting: VecDeque<(f64, f64, f64)>,
    distance_m: f64,
    max_speed_mps: f64,
    /// Time and speed of the frame before.
    last: Option<(f64, f64)>,
}

impl RideAnalysis {
    /// An analysis of frames `fs_hz` apart, from a log whose header has
    /// `config` lines.
    #[must_use]
    pub fn new(fs_hz: f64, config: &[String]) -> Self {
        Self {
            period_s: 1.0 / fs_hz,
            search: EpisodeSearch::new(fs_hz),
            kicks: wheel_circumference_m(config)
                .ok()
                .filter(|_| fs_hz.is_finite() && fs_hz > 0.0)
                .map(|wheel_m| KickSearch::new(fs_hz, wheel_m)),
            kicks_given: 0,
            // The weave's fit takes no wheel tone: any circumference does.
            weave: KickSearch::for_mode(KickMode::Weave, fs_hz, 1.0),
            waiting: VecDeque::new(),
            distance_m: 0.0,
            max_speed_mps: 0.0,
            last: None,
        }
    }

    /// Takes the next frame in file order: time, steering angle, speed,
    /// roll rate.
    pub fn push(&mut self, t_s: f64, steer_deg: f64, speed_mps: f64, roll_rate_dps: f64) {
        self.weave.push(t_s, roll_rate_dps, speed_mps);
        if let Some((t0, v0)) = self.last.filter(|&(t0, _)| follows(t0, t_s, self.period_s)) {
            self.distance_m += 0.5 * (speed_mps + v0) * (t_s - t0);
        }
        self.last = Some((t_s, speed_mps));
        self.max_speed_mps = self.max_speed_mps.max(speed_mps);
        let Some(kicks) = &mut self.kicks else {
            self.search.push(t_s, steer_deg, speed_mps);
            return;
        };
        kicks.push(t_s, steer_deg, speed_mps);
        self.waiting.push_back((t_s, steer_deg, speed_mps));
        // An episode measured when a frame arrives lies before it; the
        // kick it is rose at most [`MATCH_S`] after its largest swing.
        let settled_s = kicks.settled_s();
        self.search.add_kicks(&kicks.found()[self.kicks_given..]);
        self.kicks_given = kicks.found().len();
        while let Some(&(t_s, steer_deg, speed_mps)) = self.waiting.front() {
            if t_s + MATCH_S >= settled_s {
                break;
            }
            self.search.push(t_s, steer_deg, speed_mps);
            self.waiting.pop_front();
        }
    }

    /// The ride of the log at `path`, which `summary` describes.
    #[must_use]
    pub fn finish(mut self, path: &Path, summary: Summary) -> Ride {
        let kicks = self.kicks.map(|search| {
            let kicks = search.finish();
            self.search.add_kicks(&kicks[self.kicks_given..]);
            for (t_s, steer_deg, speed_mps) in self.waiting.drain(..) {
                self.search.push(t_s, steer_deg, speed_mps);
            }
            kicks
        });
        let mut episodes = self.search.finish(&summary.losses);
        if let Some(kicks) = &kicks {
            give_kick_values(&mut episodes, kicks.clone(), &summary.kick_records);
        }
        Ride {
            path: path.to_path_buf(),
            episodes,
            summary,
            distance_m: self.distance_m,
            max_speed_mps: self.max_speed_mps,
            host_kicks: kicks,
            weave_kicks: self.weave.finish(),
        }
    }
}
