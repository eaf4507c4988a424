//! A ride with kicks under QEMU: the simulated test bicycle speeding up from
//! 0.55 to 0.95 of its wobble speed, knocked on the bar every 5 s
//! (`campaign::speed_up_ride`). The firmware's tasks must write each kick's
//! ring-down record and the margin warning's records to the card image:
//! exactly the records the host's replay of the card's own frames makes
//! (`wobblog detect`, the same core code on the same input, so the
//! sampler's wiring is what is checked), the kicks within the on-board
//! measurement's accuracy of their truth, and the warning before the
//! wobble speed.

use std::path::{Path, PathBuf};

use wobble_core::format::{KickRingDown, MarginRecord, MarginState};
use wobble_hil::corpus::simulated::campaign::{self, SpeedUp};
use wobble_hil::corpus::simulated::Simulation;
use wobble_hil::qemu::{self, decode, fixture, DetectorBench, Outcome, Scenario};

const PLAN: SpeedUp = SpeedUp {
    fractions: (0.55, 0.95),
    duration_s: 90.0,
    kick_every_s: 5.0,
};
const SEED: u64 = 7;

/// The ride (the test bicycle), its wobble speed, its frame count, and the
/// image's run of it: as a ride, or (`bench`) timing the detector over it.
fn run_ride(bench: bool) -> (Simulation, f64, usize, PathBuf, Outcome) {
    let variant = &campaign::variants().expect("variants")[0];
    let (sim, wobble_speed) = campaign::speed_up_ride(variant, &PLAN, SEED).expect("ride");
    let rows = sim.fixture.rows().expect("rows");
    let frames = u32::try_from(rows.len()).expect("frames");
    let end_us = u64::from(frames) * fixture::FRAME_US;
    let gps = fixture::gps_schedule(qemu::GPS_CAPTURE, qemu::GPS_START_US, end_us).expect("gps");
    let name = if bench { "kicks_cost" } else { "kicks" };
    let dir = qemu::work_dir(Path::new(env!("CARGO_TARGET_TMPDIR")), name).expect("dir");
    let setup = qemu::Setup {
        dir: dir.clone(),
        scenario: Scenario {
            bench_detector: bench,
            ..Scenario::ride(frames)
        },
        rows: &rows,
        gps: &gps,
        config: None,
    };
    let out = qemu::run(&setup, |_| Ok(()), |_| {}).expect("qemu run");
    (sim, wobble_speed, rows.len(), dir, out)
}

/// The detector's cost on this ride, with the ring-down fits and margin
/// estimates it makes (`qemu_detector_cost.rs` times a ride without kicks),
/// within the per-sample budgets.
#[test]
fn the_detector_cost_on_a_ride_with_kicks() {
    let (_, _, frames, _, out) = run_ride(true);
    assert_eq!(out.code, 0, "{:?}", out.lines);
    let b = out.detector_bench().expect("BENCH line");
    assert_eq!(b.samples, frames as u64);
    // The card's 13 kick records and 4 estimates (its fifth margin record
    // is the warning).
    assert!(b.kicks >= 10 && b.estimates >= 3, "{b:?}");
    println!(
        "FIGURES detector cost, ride with kicks: {} instructions per sample on average over {} \
         samples; worst sample {} (sample {}); worst sample with a kick {} (of it the margin \
         estimate {}); {} kicks measured, {} margin estimates, {} alert changes",
        b.mean,
        b.samples,
        b.worst,
        b.worst_at,
        b.worst_kick,
        b.worst_margin,
        b.kicks,
        b.estimates,
        b.alert_changes
    );
    assert!(b.mean <= DetectorBench::MEAN_BUDGET, "{b:?}");
    assert!(b.worst <= DetectorBench::WORST_BUDGET, "{b:?}");
}

#[test]
fn a_ride_with_kicks_writes_kick_and_margin_records() {
    let (sim, wobble_speed, frames, dir, out) = run_ride(false);
    assert_eq!(out.code, 0, "{:?}", out.lines);
    let logs = decode::logs(&out.card, &dir).expect("decode");
    assert_eq!(logs.len(), 1);
    let log = &logs[0];
    assert_eq!(log.frames.len(), frames);
    assert_eq!(log.stats.unknown_records, 0);

    // The kicks measured on board, within 0.3 1/s and 0.2 Hz of their truth
    // for at least 70 % of them (the frame k of the card is row k of the
    // ride). The 80 % accuracy goal is scored over many more kicks by
    // `kick_rides`; of this ride's 17 kicks 13 are measured, all within.
    let truth: Vec<_> = sim
        .fixture
        .truth
        .events
        .iter()
        .filter(|e| e.kind == "kick")
        .collect();
    assert!(truth.len() >= 15, "{} kicks", truth.len());
    let ride_s = |t_us: u64| out.frame_index(t_us) as f64 / 100.0;
    let mut good = 0;
    for t in &truth {
        let Some(k) = log
            .kicks
            .iter()
            .find(|k| (ride_s(k.t_us) - t.t_s).abs() < 0.5)
        else {
            continue;
        };
        let sigma_err = f64::from(k.sigma_per_s()) + t.decay_per_s;
        let freq_err = f64::from(k.freq_hz()) - t.freq_hz;
        if sigma_err.abs() <= 0.3 && freq_err.abs() <= 0.2 {
            good += 1;
        }
    }
    assert!(
        good * 10 >= truth.len() * 7,
        "{good} of {} kicks within 0.3 1/s and 0.2 Hz: {:?}",
        truth.len(),
        log.kicks
    );

    // The host's replay of the card's frames makes the same records (its
    // times count from the log's first frame, the card's from boot).
    let path = dir.join(&log.name);
    let config = wobblog::cmd::detect::log_config(&log.summary.config, &[]).expect("config");
    let replay = wobblog::cmd::detect::replay_log(&path, &config).expect("replay");
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let first_us = (replay.span_s.expect("frames").0 * 1e6).round() as u64;
    let offset_us = log.frames[0].t_us - first_us;
    let replayed: Vec<_> = replay
        .kicks
        .iter()
        .map(|k| {
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            let t_us = (k.t_s * 1e6).round() as u64 + offset_us;
            // `k.t_s` is the kick's time already.
            KickRingDown {
                t_us,
                ..k.kick.to_record(0, 100.0)
            }
        })
        .collect();
    assert_eq!(replayed.len(), log.kicks.len());
    for (host, card) in replayed.iter().zip(&log.kicks) {
        assert!(host.t_us.abs_diff(card.t_us) <= 10, "{host:?} {card:?}");
        assert_eq!(
            (host.sigma_milli_per_s, host.freq_chz, host.speed_mm_s),
            (card.sigma_milli_per_s, card.freq_chz, card.speed_mm_s),
            "{host:?} {card:?}"
        );
    }
    let host_margins: Vec<_> = replay
        .margins
        .iter()
        .map(|m| MarginRecord {
            t_us: m.record.t_us + offset_us,
            ..m.record
        })
        .collect();
    assert_eq!(host_margins, log.margins);

    // The warning: an estimate once enough kicks spread over the speeds,
    // and the "approaching" record before the wobble speed.
    assert!(
        log.margins.iter().any(|m| m.state == MarginState::Estimate),
        "{:?}",
        log.margins
    );
    let warned = log
        .margins
        .iter()
        .find(|m| m.state == MarginState::Approaching)
        .unwrap_or_else(|| panic!("no warning: {:?}", log.margins));
    let speed = f64::from(warned.speed_mm_s.expect("speed")) / 1000.0;
    let lower = f64::from(warned.lower_mm_s.expect("lower bound")) / 1000.0;
    println!(
        "FIGURES QEMU ride with kicks: {} kicks on the card ({good} of {} within 0.3 1/s and \
         0.2 Hz), {} margin records; warned at {:.1} s, {speed:.2} m/s, lower bound {lower:.2} m/s, \
         wobble speed {wobble_speed:.2} m/s; {:.1} s wall",
        log.kicks.len(),
        truth.len(),
        log.margins.len(),
        ride_s(warned.t_us),
        out.wall.as_secs_f64()
    );
    assert!(speed < wobble_speed, "warned at {speed} m/s");
}
