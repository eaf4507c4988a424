//! The command line: clap definitions of every subcommand (the one source of
//! help, completions and the man page) and the dispatch to their modules.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::cmd;
use crate::CliError;

/// Decode, inspect and analyse wobble-logger card logs.
#[derive(Parser)]
#[command(name = "wobblog", version, about)]
pub struct Cli {
    /// Replace an output file that is write-protected or has other hard links.
    #[arg(long, global = true)]
    force: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Summarise a log: duration, samples, dropouts, lost blocks, GPS coverage, alerts.
    Info(cmd::info::Args),
    /// Decode a log into one row per 100 Hz frame (CSV, JSON lines, Parquet) or MCAP channels.
    Decode(cmd::decode::Args),
    /// List a log's alerts, markers, faults, dropouts and damage in time order.
    Events(cmd::events::Args),
    /// Print the CONFIG.TXT a log was recorded with, ready to copy to a card.
    Config(cmd::config::Args),
    /// Write every log of a card or folder of cards as one Parquet dataset.
    Export(cmd::export::Args),
    /// Build a log from a CSV through the firmware's encoder (tests and demos).
    Encode(cmd::encode::Args),
    /// Replay a log (its own settings) or a steering CSV through the wobble detector.
    Detect(cmd::detect::Args),
    /// Replay a raw NMEA capture through the firmware's GPS path; one JSON fix per line.
    Nmea(cmd::nmea::Args),
    /// Plot a run like the seed paper's Figure 6: steering, roll, yaw rate, speed.
    Plot(cmd::plot::Args),
    /// Measure every wobble episode (frequency, growth rate, speed); Figure 8 with --plot.
    Wobble(cmd::wobble::Args),
    /// Predict the wobble speed from handlebar kicks below it, with its 95 % interval.
    Margin(cmd::margin::Args),
    /// One self-contained HTML page: the campaign, and every run zoomable with its events.
    Report(cmd::report::Args),
    /// Write a run's GPS track as GPX.
    Gpx(cmd::gpx::Args),
    /// One row per run in a directory: duration, distance, episodes, wobble speed, losses.
    Summary(cmd::summary::Args),
    /// The linear bicycle models: eigenvalues against speed, plots, parameter studies, fits.
    #[command(subcommand)]
    Model(cmd::model::Command),
    /// Print the logger's field self-test report (SELFTEST.TXT from the card).
    Selftest(cmd::selftest::Args),
    /// Print a shell completion script (bash, zsh, fish, ...).
    Completions(cmd::completions::Args),
    /// Print the man page (roff) of wobblog.
    Man,
}

/// Parses the command line, runs the command and reports a failure on
/// stderr; the exit code says what kind of failure it was.
#[must_use]
pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return clap_exit(&e),
    };
    crate::output::set_force(cli.force);
    let result = match cli.command {
        Command::Info(args) => cmd::info::run(&args),
        Command::Decode(args) => cmd::decode::run(&args),
        Command::Events(args) => cmd::events::run(&args),
        Command::Config(args) => cmd::config::run(&args),
        Command::Export(args) => cmd::export::run(&args),
        Command::Encode(args) => cmd::encode::run(&args),
        Command::Detect(args) => cmd::detect::run(&args),
        Command::Nmea(args) => cmd::nmea::run(&args),
        Command::Plot(args) => cmd::plot::run(&args),
        Command::Wobble(args) => cmd::wobble::run(&args),
        Command::Margin(args) => cmd::margin::run(&args),
        Command::Report(args) => cmd::report::run(&args),
        Command::Gpx(args) => cmd::gpx::run(&args),
        Command::Summary(args) => cmd::summary::run(&args),
        Command::Model(command) => cmd::model::run(&command),
        Command::Selftest(args) => cmd::selftest::run(&args),
        Command::Completions(args) => cmd::completions::run(&args),
        Command::Man => cmd::completions::man(),
    };
    report(result)
}

/// Prints what clap stopped at (help, version, a usage error) and ends as
/// it would, except that help or version text that cannot be written (`--help
/// > /dev/full`) is a failure; a reader gone (`--help | head`) is not.
fn clap_exit(e: &clap::Error) -> ExitCode {
    let code = ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2));
    if e.use_stderr() {
        let _ = e.print();
        return code;
    }
    let written = e.print().and_then(|()| {
        use std::io::Write;
        std::io::stdout().flush()
    });
    match written {
        Ok(()) => code,
        Err(io) if io.kind() == std::io::ErrorKind::BrokenPipe => ExitCode::SUCCESS,
        Err(io) => {
            eprintln!("wobblog: standard output: {io}");
            ExitCode::FAILURE
        }
    }
}

fn report(result: Result<(), CliError>) -> ExitCode {
    match result {
        Ok(()) | Err(CliError::PipeClosed) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("wobblog: {err}");
            ExitCode::from(err.exit_code())
        }
    }
}
