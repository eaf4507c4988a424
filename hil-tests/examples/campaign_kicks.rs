//! Every kick of simulated kick-test campaigns (`corpus::simulated::campaign`)
//! as the host measures it from the steering and as the on-board detector
//! measures it, beside its truth: one CSV line per true kick, for studying
//! the margin regression and the kicks' uncertainties over many campaigns.
//!
//! ```text
//! SEEDS=100..112 cargo run -p wobble-hil --release --example campaign_kicks > kicks.csv
//! ```
//! `PUSH=1` rides the campaigns with pushes instead of knocks;
//! `VARIANTS=unseen` rides the bicycles no calibration was tuned on
//! (`campaign::unseen_variants`) instead of the four usual ones;
//! `VARIANTS=paper-bar-bag,paper-balloon-tyres` the bicycles so named.

use wobble_core::config::Config;
use wobble_hil::corpus::signal::WHEEL_CIRCUMFERENCE_M;
use wobble_hil::corpus::simulated::campaign::{self, Plan};
use wobble_hil::kick_metrics;
use wobblog::analysis::{find_kicks, Run};

fn main() -> Result<(), String> {
    let seeds = std::env::var("SEEDS").unwrap_or_else(|_| "100..112".into());
    let (from, to) = seeds
        .split_once("..")
        .and_then(|(a, b)| Some((a.parse::<u64>().ok()?, b.parse::<u64>().ok()?)))
        .ok_or("SEEDS is FROM..TO")?;
    let plan = if std::env::var("PUSH").is_ok() {
        Plan::default().with_push()
    } else {
        Plan::default()
    };
    println!(
        "variant,seed,wobble_speed_mps,t_s,true_speed_mps,true_sigma_per_s,true_freq_hz,\
         host_speed_mps,host_sigma_per_s,host_sd_per_s,host_freq_hz,\
         card_speed_mps,card_sigma_per_s,card_se_per_s,card_freq_hz,card_segments"
    );
    // VARIANTS=unseen rides the bicycles nothing was tuned on; a list of
    // names, those bicycles of either set.
    let variants = match std::env::var("VARIANTS").ok().as_deref() {
        None => campaign::variants()?,
        Some("unseen") => campaign::unseen_variants()?,
        Some(names) => {
            let mut all = campaign::variants()?;
            all.extend(campaign::unseen_variants()?);
            let wanted: Vec<&str> = names.split(',').collect();
            all.retain(|v| wanted.contains(&v.name));
            if all.len() != wanted.len() {
                return Err(format!(
                    "VARIANTS={names}: a name is not a campaign bicycle"
                ));
            }
            all
        }
    };
    for v in &variants {
        for seed in from..to {
            let c = campaign::simulate(v, &plan, seed)?;
            for pass in &c.passes {
                let rows = pass.fixture.rows()?;
                let run = Run {
                    t_s: rows.iter().map(|r| r.t_s).collect(),
                    steer_deg: rows.iter().map(|r| f64::from(r.steer_deg)).collect(),
                    speed_mps: rows.iter().map(|r| f64::from(r.speed_mps)).collect(),
                    ..Run::default()
                };
                let host = find_kicks(&run, WHEEL_CIRCUMFERENCE_M);
                let (_, card) = kick_metrics::replay(&pass.fixture, &Config::default())?;
                let log = format!("{}.wbl", pass.fixture.truth.name);
                for k in c.kicks.iter().filter(|k| k.log == log) {
                    let h = host.iter().find(|h| (h.t_s - k.t_s).abs() < 0.5);
                    let b = card.iter().find(|(t, _)| (t - k.t_s).abs() < 0.5);
                    let hs = h.map_or(",,,".into(), |h| {
                        format!(
                            "{},{},{},{}",
                            h.speed_mps, h.sigma_per_s, h.sigma_sd_per_s, h.freq_hz
                        )
                    });
                    let bs = b.map_or(",,,,".into(), |(_, b)| {
                        format!(
                            "{},{},{},{},{}",
                            b.speed_mps.map_or(String::new(), |s| s.to_string()),
                            b.sigma_per_s,
                            b.sigma_se_per_s,
                            b.freq_hz,
                            b.segments
                        )
                    });
                    println!(
                        "{},{seed},{},{},{},{},{},{hs},{bs}",
                        v.name, c.wobble_speed_mps, k.t_s, k.speed_mps, k.sigma_per_s, k.freq_hz
                    );
                }
            }
            eprintln!("{} {seed} done", v.name);
        }
    }
    Ok(())
}
