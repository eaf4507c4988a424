//! `wobblog report`: one self-contained HTML page for a ride or a campaign
//! of rides: the campaign's runs, its predicted wobble speed and damping
//! trend, Figure 8, and per run its signals on a zoomable time axis with
//! everything the log records drawn and listed, a spectrogram, the GPS
//! track, the configuration and the damage. Every number comes from the
//! analyses behind the other commands; only the drawing is new.

pub mod page;
pub mod ride;
pub mod series;
pub mod spectrogram;
pub mod track;

use std::path::{Path, PathBuf};

use crate::analysis::margin::{Trend, RIDE_MARGIN};
use crate::cmd::logs::{for_each_log, warn_losses};
use crate::cmd::margin::{self, KickRow, Report as MarginReport};
use crate::cmd::model::episodes::LoggedEpisode;
use crate::plot::modes::ModePlot;
use crate::plot::svg_inline;
use crate::CliError;
pub use ride::RideView;

/// Speeds of the model's curve on Figure 8, m/s (as `model compare`).
const MODEL_SPEEDS: &str = "0:10:0.05";

/// Everything the page shows.
pub struct Campaign {
    /// Each run, in the order of the logs.
    pub rides: Vec<RideView>,
    /// What `wobblog margin --json` prints for the same logs.
    pub margin: MarginReport,
    /// `margin`'s answer in words.
    pub margin_words: String,
    /// The damping-trend figure, SVG (or why there is none).
    pub margin_svg: Result<String, String>,
    /// Figure 8, SVG (over the model when one is given).
    pub modes_svg: Result<String, String>,
    /// The parameter file's name, when given.
    pub model_file: Option<String>,
}

impl Campaign {
    /// Reads and analyses `logs`, with the model in `params` when given.
    /// A log that cannot be read fails the whole: a report that silently
    /// missed a run would mislead.
    pub fn load(logs: &[PathBuf], params: Option<&Path>) -> Result<Self, CliError> {
        let mut rides = Vec::new();
        for_each_log(logs, "reading", |log| {
            let ride = RideView::load(log)?;
            warn_losses(log, &ride.summary);
            rides.push(ride);
            Ok(())
        })?;
        // The kicks as `margin` gathers them: log by log, each in time
        // order (moved, not copied: a log can hold 100 000 card records).
        let rows = rides
            .iter_mut()
            .flat_map(|r| {
                let log = &r.path;
                std::mem::take(&mut r.kicks)
                    .into_iter()
                    .map(|kick| KickRow {
                        log: log.clone(),
                        kick,
                        used: false,
                    })
            })
            .collect();
        let (margin, prediction) =
            margin::campaign_of(rows, Trend::Line, RIDE_MARGIN, params, &[])?;
        let margin_words = margin::answer_text(&margin, logs.len());
        let margin_svg = svg_inline(&margin::figure(&margin, prediction));
        let modes_svg = match params {
            Some(params) => model_figure(params, &rides)?,
            None => svg_inline(&ModePlot::new(
                rides
                    .iter()
                    .map(|r| (r.name.clone(), r.episodes.clone()))
                    .collect(),
            )),
        };
        Ok(Self {
            rides,
            margin,
            margin_words,
            margin_svg,
            modes_svg,
            model_file: params.map(crate::analysis::run::log_name),
        })
    }

    /// How many of the campaign's kicks come from `ride`.
    #[must_use]
    pub fn kicks_of(&self, ride: &RideView) -> usize {
        self.margin
            .kicks
            .iter()
            .filter(|k| k.log == ride.path)
            .count()
    }
}

/// Figure 8 over the model of `params`, as `model compare` draws it.
fn model_figure(params: &Path, rides: &[RideView]) -> Result<Result<String, String>, CliError> {
    use crate::cmd::model::{compare, load, Speeds};
    let (set, model) = load(params, false)?;
    let speeds: Speeds = MODEL_SPEEDS.parse().map_err(CliError::Failed)?;
    let found: Vec<LoggedEpisode> = rides
        .iter()
        .flat_map(|r| {
            r.episodes.iter().map(|e| LoggedEpisode {
                log: r.name.clone(),
                episode: e.clone(),
            })
        })
        .collect();
    let figure = compare::figure(&set.name, &model, &speeds.0, params, &found)?;
    Ok(svg_inline(&figure))
}
