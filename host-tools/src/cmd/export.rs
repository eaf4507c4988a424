//! `wobblog export`: every log of a card, or of a folder of cards, as
//! Parquet datasets, one per table.

use std::path::PathBuf;

use indicatif::ProgressBar;

use crate::cmd::logs::warn_losses;
use crate::dataset::{build, campaign_logs, Outcome};
use crate::CliError;

const AFTER_HELP: &str = "\
Layout: one folder per table, each a dataset of its own:
  DATASET/frames/RUN00001.parquet       one file per run, a `run` column
                                        then the columns of `wobblog decode`
                                        (under card=NAME/ for a folder of cards)
  DATASET/runs/part-0.parquet           one row per run, as `wobblog summary`
  DATASET/episodes/part-0.parquet       one row per episode, wobble and weave,
                                        as `wobblog wobble`, censoring included
  DATASET/kicks/part-0.parquet          one row per kick, as `wobblog margin`
                                        takes them, with whether it was used
  DATASET/events/part-0.parquet         one row per event, as `wobblog events`
Every table has a `run` column; a card's name is a Hive partition of the
frames, percent-encoded as readers decode it (card=rider%3Danna), and a
`card` column of the other tables. Every file carries its columns' units as
metadata (unit.NAME). Default options open it:
  polars.scan_parquet('DATASET/frames/')
  pyarrow.parquet.read_table('DATASET/frames')
  duckdb: SELECT run, max(steer_deg) FROM 'DATASET/frames/**/*.parquet' GROUP BY run;
          SELECT * FROM 'DATASET/episodes/*.parquet' WHERE stability = 'unstable';
A log that cannot be read is reported and left out (exit code 1, the
dataset holds the others) unless --strict. The dataset appears whole or not
at all; an existing DATASET is refused.";

/// Arguments of `wobblog export`.
#[derive(clap::Args)]
#[command(after_help = AFTER_HELP)]
pub struct Args {
    /// A card (logs at its top) or a folder of cards (one directory each).
    pub dir: PathBuf,
    /// The dataset directory to create.
    #[arg(short, long, value_name = "DATASET")]
    pub output: PathBuf,
    /// Write no dataset at all if any log cannot be read.
    #[arg(long)]
    pub strict: bool,
}

/// Runs `wobblog export`.
pub fn run(args: &Args) -> Result<(), CliError> {
    let entries = campaign_logs(&args.dir)?;
    let bar = if entries.len() > 1 {
        ProgressBar::new(entries.len() as u64)
    } else {
        ProgressBar::hidden()
    };
    let skipped = build(&entries, &args.output, args.strict, |_, outcome| {
        match outcome {
            Outcome::Written(ride) => bar.suspend(|| warn_losses(&ride.path, &ride.summary)),
            Outcome::Skipped(err) => {
                bar.suspend(|| eprintln!("wobblog: {err}; left out of the dataset"));
            }
        }
        bar.inc(1);
    })?;
    bar.finish_and_clear();
    eprintln!(
        "wobblog: {}: {} written",
        crate::text::shown(&args.output),
        crate::words::plural(entries.len() - skipped, "run")
    );
    if skipped > 0 {
        return Err(CliError::Failed(format!(
            "{} of {} logs could not be read (see above) and were left out; --strict writes no dataset then",
            skipped,
            entries.len()
        )));
    }
    Ok(())
}
