//! Measured episodes of card logs, from the `wobblog wobble` analysis
//! (the wobble's and the weave's ring-downs), as points to compare with and
//! fit the model to.

use std::path::{Path, PathBuf};

use wobble_model::fit::Observation;
use wobble_model::Mode;

use super::figure::Measured;
use crate::analysis::{Episode, KickMode, Ride};
use crate::cmd::logs::{for_each_log, warn_losses};
use crate::CliError;

/// One episode with the log it came from.
pub struct LoggedEpisode {
    /// The log's file name.
    pub log: String,
    /// The episode.
    pub episode: Episode,
}

impl LoggedEpisode {
    /// The model's mode it measures.
    #[must_use]
    pub fn mode(&self) -> Mode {
        match self.episode.mode {
            KickMode::Wobble => Mode::Wobble,
            KickMode::Weave => Mode::Weave,
        }
    }

    /// Whether the episode may not be fitted: the analysis marks it
    /// censored when a gap or an end of the data cut it.
    #[must_use]
    pub fn censored(&self) -> bool {
        self.episode.censored
    }

    /// The point drawn for it.
    #[must_use]
    pub fn measured(&self) -> Measured {
        Measured {
            speed_mps: self.episode.speed_at_onset_mps,
            sigma_per_s: self.episode.sigma_per_s,
            freq_hz: self.episode.freq_hz,
            censored: self.censored(),
        }
    }

    /// The observation a fit uses.
    #[must_use]
    pub fn observation(&self) -> Observation {
        Observation {
            speed_mps: self.episode.speed_at_onset_mps,
            freq_hz: self.episode.freq_hz,
            sigma_per_s: self.episode.sigma_per_s,
        }
    }
}

/// Every episode of `logs`, the weave's among the wobble's. A log that cannot be read is reported and
/// skipped; the error then says so after the others were used.
pub fn load(logs: &[PathBuf]) -> (Vec<LoggedEpisode>, Result<(), CliError>) {
    let mut out = Vec::new();
    let result = for_each_log(logs, "analysing", |log: &Path| {
        let ride = Ride::load(log)?;
        warn_losses(log, &ride.summary);
        let name = ride.name();
        out.extend(
            ride.all_episodes()
                .into_iter()
                .map(|episode| LoggedEpisode {
                    log: name.clone(),
                    episode,
                }),
        );
        Ok(())
    });
    (out, result)
}
