//! How `margin` pairs the card's kick records with the host's own fits:
//! one record beside two host kicks goes to one of them only, and the
//! kicks come out in time order whatever their source.

use std::f64::consts::TAU;

use wobble_core::format::KickRingDown;
use wobblog::analysis::campaign_kicks::{campaign_kicks, Prefer, Source};
use wobblog::analysis::Run;

/// A 10 s run at 3 m/s with a ring of 1.5 degrees at 7 Hz decaying at
/// `sigma` from each time of `kicks_s`, and the card's `records`.
fn run(kicks_s: &[f64], sigma: f64, records: Vec<KickRingDown>) -> Run {
    let t_s: Vec<f64> = (0..1000).map(|i| f64::from(i) / 100.0).collect();
    let steer_deg = t_s
        .iter()
        .map(|&t| {
            kicks_s
                .iter()
                .map(|&k| {
                    let tau = t - k;
                    if tau >= 0.0 {
                        1.5 * (sigma * tau).exp() * (TAU * 7.0 * tau).sin()
                    } else {
                        0.0
                    }
                })
                .sum()
        })
        .collect();
    let mut run = Run {
        speed_mps: vec![3.0; t_s.len()],
        t_s,
        steer_deg,
        ..Run::default()
    };
    run.summary.kick_records = records;
    run
}

fn record(t_s: f64) -> KickRingDown {
    KickRingDown {
        t_us: (t_s * 1e6) as u64,
        speed_mm_s: Some(3000),
        freq_chz: 700,
        sigma_milli_per_s: -2500,
        sigma_se_milli_per_s: 50,
        amp_cdeg: 150,
        segments: 9,
    }
}

#[test]
fn one_card_record_beside_two_host_kicks_pairs_with_one() {
    // Host kicks at 1.96 and 2.91 s (their rises), the record between,
    // within MATCH_S (0.5 s) of both.
    let run = run(&[2.0, 2.95], -6.0, vec![record(2.435)]);
    let kicks = campaign_kicks(&run, 2.2, Prefer::Best);
    let paired = kicks.iter().filter(|k| k.card.is_some()).count();
    assert_eq!(paired, 1, "{kicks:?}");
    assert_eq!(kicks.len(), 2, "{kicks:?}");
}

#[test]
fn kicks_come_out_in_time_order() {
    // The card's record at 1 s has no host kick beside it (nothing rings
    // there); the host's kick at 5 s has no record.
    let run = run(&[5.0], -1.0, vec![record(1.0)]);
    let kicks = campaign_kicks(&run, 2.2, Prefer::Best);
    let sources: Vec<Source> = kicks.iter().map(|k| k.source).collect();
    assert_eq!(sources, [Source::Card, Source::Host], "{kicks:?}");
    assert!(kicks.windows(2).all(|w| w[0].t_s <= w[1].t_s), "{kicks:?}");
}
