//! `detector-metrics`: runs the on-board detector over the corpus and writes
//! the metrics table.
//!
//! ```text
//! cargo run -p wobble-hil --release --bin detector-metrics            # writes METRICS.md
//! cargo run -p wobble-hil --release --bin detector-metrics -- --stdout
//! cargo run -p wobble-hil --release --bin detector-metrics -- --trace NAME  # per-hop estimates as CSV
//! cargo run -p wobble-hil --release --bin detector-metrics -- --false  # each false alert and its cause
//! ```
//! Both corpus families (the signal models and the rides simulated from the
//! bicycle model) are generated in memory from the same code as the
//! committed fixtures (tests assert they are identical).

use std::process::ExitCode;

use wobble_core::config::Config;
use wobble_hil::{corpus, metrics};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let fixtures = corpus::generate();
    if let Some(i) = args.iter().position(|a| a == "--trace") {
        let Some(name) = args.get(i + 1) else {
            eprintln!("detector-metrics: --trace needs a fixture name");
            return ExitCode::from(2);
        };
        let Some(fx) = fixtures.iter().find(|f| &f.truth.name == name) else {
            eprintln!("detector-metrics: no fixture {name}");
            return ExitCode::from(2);
        };
        let rows = match fx.rows() {
            Ok(r) => r,
            Err(e) => {
                eprintln!("detector-metrics: {name}: {e}");
                return ExitCode::FAILURE;
            }
        };
        println!("{}", metrics::TRACE_HEADER);
        let mut print = |t: f64, e: wobble_core::detector::Estimate, on: bool| {
            println!("{}", metrics::trace_line(t, &e, on));
        };
        return match metrics::replay(&rows, &Config::default(), true, Some(&mut print)) {
            Ok(_) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("detector-metrics: {e}");
                ExitCode::FAILURE
            }
        };
    }
    let (report, no_speed) = match (
        metrics::evaluate(&fixtures, &Config::default(), true),
        metrics::evaluate(&fixtures, &Config::default(), false),
    ) {
        (Ok(a), Ok(b)) => (a, b),
        (Err(e), _) | (_, Err(e)) => {
            eprintln!("detector-metrics: {e}");
            return ExitCode::FAILURE;
        }
    };
    if args.iter().any(|a| a == "--false") {
        // Every false alert with the nearest ground-truth event before it.
        for (f, fx) in report.fixtures.iter().zip(&fixtures) {
            for &t in &f.false_alerts {
                let near = fx.truth.events.iter().rfind(|e| e.t_s <= t);
                match near {
                    Some(e) => println!(
                        "{} {t:.2}: {} at {:.2} ({:.2} deg, {:.2} Hz, decay {:.1}/s, {:.1} m/s)",
                        f.name, e.kind, e.t_s, e.amp_deg, e.freq_hz, e.decay_per_s, e.speed_mps
                    ),
                    None => println!("{} {t:.2}: no event before", f.name),
                }
            }
        }
        return ExitCode::SUCCESS;
    }
    let simulated = match corpus::simulated::generate()
        .and_then(|f| metrics::evaluate(&f, &Config::default(), true))
    {
        Ok(r) => r,
        Err(e) => {
            eprintln!("detector-metrics: simulated family: {e}");
            return ExitCode::FAILURE;
        }
    };
    let md = metrics::markdown(&report, &no_speed) + &metrics::simulated_markdown(&simulated);
    if args.iter().any(|a| a == "--stdout") {
        print!("{md}");
        return ExitCode::SUCCESS;
    }
    let path = corpus::corpus_dir().join("METRICS.md");
    if let Err(e) = std::fs::write(&path, &md) {
        eprintln!("detector-metrics: {}: {e}", path.display());
        return ExitCode::FAILURE;
    }
    print!("{md}");
    println!("wrote {}", path.display());
    ExitCode::SUCCESS
}
