//! `wobblog export`: every log of a card, or of a folder of cards, as one
//! Hive-partitioned Parquet dataset.

use std::path::PathBuf;

use indicatif::ProgressBar;

use crate::cmd::logs::warn_losses;
use crate::dataset::{build, campaign_logs};
use crate::CliError;

const AFTER_HELP: &str = "\
Layout: DATASET/run=00001/part-0.parquet (one file per run, the columns of
`wobblog decode`), DATASET/runs.parquet (one row per run, as `wobblog
summary`) and DATASET/episodes.parquet (one row per wobble episode, as
`wobblog wobble`). For a folder of cards, each card's runs go under
DATASET/card=NAME/. Query it with DuckDB, for example:
  SELECT run, max(steer_deg) FROM read_parquet('DATASET/**/run=*/*.parquet',
    hive_partitioning = true, hive_types = {'run': INTEGER}) GROUP BY run;
  SELECT * FROM 'DATASET/episodes.parquet' WHERE stability = 'unstable';
The dataset appears whole or not at all; an existing DATASET is refused.";

/// Arguments of `wobblog export`.
#[derive(clap::Args)]
#[command(after_help = AFTER_HELP)]
pub struct Args {
    /// A card (logs at its top) or a folder of cards (one directory each).
    pub dir: PathBuf,
    /// The dataset directory to create.
    #[arg(short, long, value_name = "DATASET")]
    pub output: PathBuf,
}

/// Runs `wobblog export`.
pub fn run(args: &Args) -> Result<(), CliError> {
    let entries = campaign_logs(&args.dir)?;
    let bar = if entries.len() > 1 {
        ProgressBar::new(entries.len() as u64)
    } else {
        ProgressBar::hidden()
    };
    build(&entries, &args.output, |_, run| {
        bar.suspend(|| warn_losses(&run.path, &run.summary));
        bar.inc(1);
    })?;
    bar.finish_and_clear();
    eprintln!(
        "wobblog: {}: {} written",
        args.output.display(),
        crate::words::plural(entries.len(), "run")
    );
    Ok(())
}
