//! The kick tests below the wobble speed (`wobble_hil::corpus::kicks`): for
//! the default configuration and each `key=value[,key=value...]` variant,
//! how many ring-downs the on-board alert fired on, and each such kick.
//!
//! ```text
//! cargo run -p wobble-hil --release --example kicks -- detector.decay_ratio=0.8
//! SEED=7 cargo run ...   # another draw of the rides
//! ```

use wobble_core::config::Config;
use wobble_hil::corpus::kicks;
use wobble_hil::{kick_metrics, metrics};

fn main() -> Result<(), String> {
    let seed = std::env::var("SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let signal = kicks::signal_rides(seed, 9);
    let simulated = kicks::simulated_rides(seed, &kicks::SIMULATED_SPEEDS)?;
    if let Ok(spec) = std::env::var("TRACE") {
        // TRACE=ride:from_s:to_s prints the detector's estimate per analysis.
        let mut it = spec.split(':');
        let (name, from, to) = (
            it.next().unwrap_or(""),
            it.next().and_then(|s| s.parse().ok()).unwrap_or(0.0),
            it.next()
                .and_then(|s| s.parse().ok())
                .unwrap_or(f64::INFINITY),
        );
        for fx in signal
            .iter()
            .chain(&simulated)
            .filter(|f| f.truth.name == name)
        {
            println!("{}", metrics::TRACE_HEADER);
            let mut print = |t: f64, e, alert| {
                if (from..=to).contains(&t) {
                    println!("{}", metrics::trace_line(t, &e, alert));
                }
            };
            metrics::replay(&fx.rows()?, &Config::default(), true, Some(&mut print))
                .map_err(|e| e.to_string())?;
        }
        return Ok(());
    }
    let mut variants = vec![("default".to_owned(), Config::default())];
    for spec in std::env::args().skip(1) {
        variants.push((spec.clone(), metrics::override_config(&spec)?));
    }
    for (name, c) in variants {
        for (family, rides) in [("signal", &signal), ("simulated", &simulated)] {
            let scores = kick_metrics::score(rides, &c)?;
            let alerted: Vec<_> = scores.iter().filter(|k| !k.alerts_s.is_empty()).collect();
            let fast = scores.iter().filter(|k| k.sigma_per_s < -1.5).count();
            let fast_alerted = alerted.iter().filter(|k| k.sigma_per_s < -1.5).count();
            println!(
                "{name} {family}: alert after {} of {} kicks ({fast_alerted} of the {fast} \
                 decaying faster than 1.5/s)",
                alerted.len(),
                scores.len()
            );
            let band: Vec<_> = scores
                .iter()
                .filter(|k| (1.5..=6.0).contains(&k.speed_mps))
                .collect();
            let good = band.iter().filter(|k| k.within(0.3, 0.2)).count();
            let measured = band.iter().filter(|k| k.measured.is_some()).count();
            println!(
                "  measured {measured} of {} kicks at 1.5-6 m/s; sigma within 0.3/s and f within \
                 0.2 Hz: {good} ({:.0} %)",
                band.len(),
                100.0 * good as f64 / band.len().max(1) as f64
            );
            if std::env::var_os("VERBOSE").is_some() {
                for k in &band {
                    let m = k.measured.map_or("-".to_owned(), |(t, m)| {
                        format!(
                            "t {t:.2} f {:.2} sigma {:.2} se {:.2} amp {:.2} v {:?} n {}",
                            m.freq_hz,
                            m.sigma_per_s,
                            m.sigma_se_per_s,
                            m.amp_deg,
                            m.speed_mps,
                            m.segments
                        )
                    });
                    println!(
                        "  {} {:.2}: v {:.2} f {:.2} sigma {:.2} amp {:.2} | {m}",
                        k.fixture, k.t_s, k.speed_mps, k.freq_hz, k.sigma_per_s, k.amp_deg
                    );
                }
            }
            for k in alerted {
                println!(
                    "  {} kick {:.2} s: {:.2} m/s, {:.2} Hz, sigma {:.2}/s, {:.2} deg; alert at {:?}",
                    k.fixture, k.t_s, k.speed_mps, k.freq_hz, k.sigma_per_s, k.amp_deg, k.alerts_s
                );
            }
        }
    }
    Ok(())
}
