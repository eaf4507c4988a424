//! Tuning aid: the corpus metrics for the default configuration and for each
//! variant given as `key=value[,key=value...]` arguments.
//!
//! ```text
//! cargo run -p wobble-hil --release --example sweep -- window_s=0.32 amp_on_deg=0.45,confirm_hops=1
//! NOSPEED=1 cargo run ...   # replay without the speed column
//! SIMULATED=1 cargo run ...  # the rides simulated from the bicycle model
//! ```

use wobble_core::config::Config;
use wobble_hil::{corpus, metrics};

fn main() -> Result<(), String> {
    let fixtures = if std::env::var_os("SIMULATED").is_some() {
        corpus::simulated::generate()?
    } else {
        corpus::generate()
    };
    let use_speed = std::env::var_os("NOSPEED").is_none();
    let mut variants = vec![("default".to_owned(), Config::default())];
    for spec in std::env::args().skip(1) {
        let c = metrics::override_config(&spec)?;
        variants.push((spec, c));
    }
    for (name, c) in variants {
        let r = metrics::evaluate(&fixtures, &c, use_speed)?;
        let errors: Vec<String> = r
            .episodes
            .iter()
            .map(|e| e.freq_error_hz().map_or("-".into(), |x| format!("{x:.2}")))
            .collect();
        println!(
            "{name}: missed {} median {:.3} worst {:.3} f-error {:.3} false (non-wobble) {} \
             false (wobble fixtures) {} | f-errors {}",
            r.missed(),
            r.median_latency_s().unwrap_or(f64::NAN),
            r.worst_latency_s().unwrap_or(f64::NAN),
            r.max_freq_error_hz().unwrap_or(f64::NAN),
            r.non_wobble_false_alerts(),
            r.wobble_fixture_false_alerts(),
            errors.join(" ")
        );
    }
    Ok(())
}
