//! Generalisation check: the corpus recipes with fresh seeds (120 random
//! episodes across 6-9 Hz and growth 0.6-4/s, 4.5 h of kicks, potholes, kerbs
//! and mixed riding), so tuning cannot overfit the committed corpus.
//!
//! ```text
//! cargo run -p wobble-hil --release --example stress [-- key=value,...]
//! NOSPEED=1 ...                      # replay without the speed column
//! TRACE=ep5 T0=12 T1=14 ...          # per-hop estimates of one ride
//! ```

use wobble_core::detector::Estimate;
use wobble_hil::corpus::{catalog, rng::Rng, signal, Fixture};
use wobble_hil::metrics;

fn main() -> Result<(), String> {
    let spec: Vec<String> = std::env::args().skip(1).collect();
    let c = metrics::override_config(&spec.join(","))?;
    let use_speed = std::env::var_os("NOSPEED").is_none();
    let mut rides = Vec::new();
    let mut rng = Rng::new(999);
    for s in 0..120u64 {
        let v = rng.range(3.0, 9.0);
        let f = (signal::wobble_mode_hz(v) + rng.range(-0.3, 0.3)).clamp(6.0, 9.0);
        let g = rng.range(0.6, 4.0);
        rides.push(catalog::episode(&format!("ep{s}"), v, f, g, 3.0, 1000 + s));
    }
    for s in 0..18u64 {
        rides.push(catalog::kicks_ride(
            &format!("kicks{s}"),
            2000 + s,
            300.0,
            "",
        ));
        rides.push(catalog::road_ride(&format!("road{s}"), 3000 + s, 300.0));
        rides.push(catalog::commute(&format!("commute{s}"), 4000 + s, 300.0));
    }
    let fixtures: Vec<Fixture> = rides
        .into_iter()
        .map(|r| {
            let (csv, truth) = r.finish(false);
            Fixture { csv, truth }
        })
        .collect();
    if let Ok(name) = std::env::var("TRACE") {
        let fx = fixtures
            .iter()
            .find(|f| f.truth.name == name)
            .ok_or("no such ride")?;
        let t0: f64 = std::env::var("T0")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(0.0);
        let t1: f64 = std::env::var("T1")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(1e9);
        println!("{:?}", fx.truth.episodes);
        println!("{}", metrics::TRACE_HEADER);
        let mut print = |t: f64, e: Estimate, on: bool| {
            if (t0..=t1).contains(&t) {
                println!("{}", metrics::trace_line(t, &e, on));
            }
        };
        metrics::replay(&fx.rows()?, &c, use_speed, Some(&mut print)).map_err(|e| e.to_string())?;
        return Ok(());
    }
    let r = metrics::evaluate(&fixtures, &c, use_speed)?;
    let mut lats = r.latencies_s();
    lats.sort_by(f64::total_cmp);
    println!(
        "missed {} median {:.3} p90 {:.3} worst {:.3} f-error {:.3} false {} in {:.0} min",
        r.missed(),
        r.median_latency_s().unwrap_or(f64::NAN),
        lats.get(lats.len() * 9 / 10).copied().unwrap_or(f64::NAN),
        r.worst_latency_s().unwrap_or(f64::NAN),
        r.max_freq_error_hz().unwrap_or(f64::NAN),
        r.false_alerts(),
        r.non_wobble_s() / 60.0
    );
    for e in &r.episodes {
        if e.latency_s().is_none_or(|l| l > 0.45) || e.freq_error_hz().is_some_and(|x| x > 0.2) {
            println!(
                "  {} f {:.2} growth {:.2} speed {:.1} latency {:?} f-error {:?}",
                e.fixture,
                e.freq_hz,
                e.growth_per_s,
                e.speed_mps,
                e.latency_s(),
                e.freq_error_hz()
            );
        }
    }
    for (f, fx) in r.fixtures.iter().zip(&fixtures) {
        for t in &f.false_alerts {
            let cause = fx.truth.events.iter().rfind(|e| e.t_s <= *t);
            println!("  false alert {} at {t:.2}: after {cause:?}", f.name);
        }
    }
    Ok(())
}
