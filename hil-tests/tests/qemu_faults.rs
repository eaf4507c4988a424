//! Faults injected through the emulated card and sensors: the logger keeps
//! sampling and alerting, loses nothing it was designed to keep, and every
//! fault and loss is in the log with its exact count.

use std::path::{Path, PathBuf};

use wobble_core::format::{DropoutReason, FaultSource, FrameStatus};
use wobble_core::logger::FAULT_CARD_ABSENT;
use wobble_hil::corpus::rng::Rng;
use wobble_hil::qemu::decode::{self, Log};
use wobble_hil::qemu::{self, fixture, Bundle, Outcome, Scenario};

/// 20 s rides: long enough for a flush period, a retry period and the
/// Figure-6 wobble (onset 12 s).
const FRAMES: u32 = 2000;

fn dir(name: &str) -> PathBuf {
    qemu::work_dir(Path::new(env!("CARGO_TARGET_TMPDIR")), name).expect("work dir")
}

fn bundle() -> Bundle {
    qemu::bundle(FRAMES).expect("fixtures")
}

fn run(
    name: &str,
    scenario: Scenario,
    prepare: impl FnOnce(&Path) -> Result<(), String>,
) -> (Outcome, Vec<Log>) {
    let bundle = bundle();
    let dir = dir(name);
    let out = qemu::run(&bundle.setup(dir.clone(), scenario), prepare, |_| {}).expect("qemu run");
    assert_eq!(out.code, 0, "{:?}", out.lines);
    assert_eq!(
        out.number("END", "frames"),
        Some(u64::from(FRAMES)),
        "sampling went on"
    );
    let logs = decode::logs(&out.card, &dir).expect("decode");
    (out, logs)
}

/// Every frame is in the log or counted as lost, exactly: the holes in the
/// frame sequence add up to the dropouts' counts.
fn assert_accounted(out: &Outcome, log: &Log, reason: DropoutReason) -> u64 {
    let lost: u64 = log
        .dropouts
        .iter()
        .filter(|d| d.reason == reason)
        .map(|d| u64::from(d.frames_lost))
        .sum();
    assert_eq!(
        log.frames.len() as u64 + lost,
        u64::from(FRAMES),
        "{:?}",
        log.dropouts
    );
    let idx: Vec<u64> = log.frames.iter().map(|f| out.frame_index(f.t_us)).collect();
    assert!(idx.windows(2).all(|w| w[1] > w[0]), "frames in order");
    let holes: u64 = idx.first().copied().unwrap_or(0)
        + idx.windows(2).map(|w| w[1] - w[0] - 1).sum::<u64>()
        + (u64::from(FRAMES) - 1).saturating_sub(idx.last().copied().unwrap_or(0));
    assert_eq!(holes, lost, "the dropouts count exactly the missing frames");
    lost
}

/// IMU faults the log's fault records count.
fn imu_faults_counted(log: &Log) -> u64 {
    log.faults
        .iter()
        .filter(|f| f.source == FaultSource::Imu)
        .map(|f| u64::from(f.count))
        .sum()
}

/// The Figure-6 wobble alerted once, within the latency goal of the ground
/// truth and at its frequency, whatever the fault.
fn assert_alerted(out: &Outcome) {
    if let Err(e) = bundle().check_alerts(&out.alert_ons()) {
        panic!("{e}; all alert changes: {:?}", out.alerts());
    }
}

#[test]
fn card_stalls_within_the_design_lose_no_frame() {
    // Stalls of 250-500 ms at random block writes (the SD specification
    // allows 500 ms); seeded, so a failure reproduces.
    let mut rng = Rng::new(0x57A1);
    let mut writes: Vec<u32> = (0..6).map(|_| rng.range(10.0, 200.0) as u32).collect();
    writes.sort_unstable();
    writes.dedup();
    let stalls = writes
        .iter()
        .map(|&w| (w, rng.range(250.0, 500.0) as u32))
        .collect();
    let (out, logs) = run(
        "stalls",
        Scenario {
            stalls,
            ..Scenario::ride(FRAMES)
        },
        |_| Ok(()),
    );
    let log = &logs[0];
    assert_eq!(log.frames.len(), FRAMES as usize);
    assert!(log.dropouts.is_empty());
    let stalled = out.lines.iter().filter(|l| l.starts_with("STALL")).count();
    assert!(stalled >= 4, "stalls happened: {stalled}");
    let high_water = out.number("END", "queue_high_water").expect("END line");
    assert!(high_water < wobble_core::channels::QUEUE_LEN as u64);
    println!("FIGURES stalls: {stalled} stalls of 250-500 ms, queue high water {high_water} of {} records", wobble_core::channels::QUEUE_LEN);
    assert_alerted(&out);
}

/// One card operation as long as the writer's worst iteration by the SD
/// specification (`channels::WORST_ITERATION_US`, 4.5 s): the queue holds
/// it, nothing is lost.
#[test]
fn a_stall_as_long_as_the_worst_writer_iteration_loses_nothing() {
    let stall_ms = (wobble_core::channels::WORST_ITERATION_US / 1000) as u32;
    let scenario = Scenario {
        stalls: vec![(60, stall_ms)],
        ..Scenario::ride(FRAMES)
    };
    let (out, logs) = run("worst_iteration_stall", scenario, |_| Ok(()));
    let log = &logs[0];
    assert_eq!(log.frames.len(), FRAMES as usize);
    assert!(log.dropouts.is_empty(), "{:?}", log.dropouts);
    assert_eq!(out.number("END", "queue_others_dropped"), Some(0));
    let high_water = out.number("END", "queue_high_water").expect("END line");
    assert!(
        high_water >= u64::from(stall_ms) / 10,
        "high water {high_water}"
    );
    assert!(high_water <= wobble_core::channels::QUEUE_LEN as u64);
    println!(
        "FIGURES worst-iteration stall: {stall_ms} ms in one card operation, queue high water \
         {high_water} of {} records, nothing lost",
        wobble_core::channels::QUEUE_LEN
    );
    assert_alerted(&out);
}

#[test]
fn stall_beyond_the_design_is_a_dropout_with_the_exact_count() {
    let scenario = Scenario {
        // 6 s: longer than the queue holds (4.6 s at the highest record
        // rate, `channels::QUEUE_HOLDS_US`).
        stalls: vec![(60, 6000)],
        ..Scenario::ride(FRAMES)
    };
    let (out, logs) = run("long_stall", scenario, |_| Ok(()));
    let log = &logs[0];
    let lost = assert_accounted(&out, log, DropoutReason::QueueFull);
    // 6 s of frames minus what the queue held (at most QUEUE_LEN records,
    // some of them GPS records).
    let held = wobble_core::channels::QUEUE_LEN as u64;
    assert!((600 - held..=600).contains(&lost), "lost {lost}");
    assert_eq!(
        out.number("END", "queue_frames_dropped"),
        Some(0),
        "every drop reported"
    );
    // The GPS task runs in its own interrupt executor, as on the board: it
    // goes on reading through the stall and meets the full queue. Every
    // fix gpsd reported up to the card's last one is on the card or among
    // the records the queue counted as dropped.
    let others = out.number("END", "queue_others_dropped").expect("END line");
    let gpsd = fixture::gpsd_fixes(qemu::GPS_CAPTURE).expect("gpsd output");
    let on_card: Vec<String> = log
        .fixes
        .iter()
        .filter(|f| f.lat_e7.is_some())
        .filter_map(|f| Some(wobblog::time::iso8601(f.utc?)))
        .collect();
    let last = on_card.last().cloned().unwrap_or_default();
    let missing = gpsd
        .iter()
        .filter(|g| g.time <= last && !on_card.contains(&g.time))
        .count() as u64;
    assert!(
        missing >= 1 && missing <= others,
        "{missing} fixes missing, {others} records dropped"
    );
    println!("FIGURES long stall: 6000 ms stall lost {lost} frames, all in one dropout record; \
              the GPS task met the full queue: {missing} fixes missing, {others} GPS records counted dropped");
    assert_alerted(&out);
}

#[test]
fn card_absent_at_boot_then_inserted() {
    let scenario = Scenario {
        card_absent_ms: Some((0, 2500)),
        ..Scenario::ride(FRAMES)
    };
    let (out, logs) = run("absent", scenario, |_| Ok(()));
    let log = &logs[0];
    let lost = assert_accounted(&out, log, DropoutReason::CardUnavailable);
    // The card is back at 2.5 s and found by the next retry (every 1 s), at
    // 3 s; the frames sampled while the file is opened are lost too.
    assert!((250..=310).contains(&lost), "lost {lost}");
    let absent: Vec<_> = log
        .faults
        .iter()
        .filter(|f| f.source == FaultSource::Card && f.code == FAULT_CARD_ABSENT)
        .collect();
    assert_eq!(absent.len(), 1);
    assert_eq!(absent[0].count, 3, "attempts at 0, 1 and 2 s failed");
    assert_eq!(qemu::card::fsck(&out.card).expect("fsck").code, 0);
    assert_alerted(&out);
}

#[test]
fn card_full_keeps_sampling_and_counts_the_loss() {
    let (out, logs) = run("full", Scenario::ride(FRAMES), |card| {
        qemu::card::fill(card, 24 * 1024)
    });
    let log = logs.first().expect("the run's file");
    let lost = out.number("END", "card_frames_lost").expect("END line");
    eprintln!(
        "DEBUG {:?} {:?}",
        out.lines
            .iter()
            .filter(|l| !l.starts_with("STALL"))
            .collect::<Vec<_>>(),
        logs.iter().map(|l| l.frames.len()).collect::<Vec<_>>()
    );
    assert!(lost > 0);
    // Each attempt on the full card searches its FAT for a free cluster,
    // hundreds of block reads at the card's latency: the writer falls
    // behind and the queue drops frames too, counted in its dropout
    // records and, after the last frame, in the END line.
    let queue_lost = logs
        .iter()
        .flat_map(|l| &l.dropouts)
        .filter(|d| d.reason == DropoutReason::QueueFull)
        .map(|d| u64::from(d.frames_lost))
        .sum::<u64>()
        + out.number("END", "queue_frames_dropped").expect("END line");
    let on_card: u64 = logs.iter().map(|l| l.frames.len() as u64).sum();
    assert_eq!(
        on_card + lost + queue_lost,
        u64::from(FRAMES),
        "on card + counted = sampled: {:?}, {:?}",
        out.fields("END"),
        log.dropouts
    );
    assert!(
        out.number("END", "card_full").unwrap_or(0) >= 1,
        "{:?}",
        out.fields("END")
    );
    assert!(log.stats.damaged_blocks == 0);
    let fsck = qemu::card::fsck(&out.card).expect("fsck");
    // embedded-sdmmc 0.10 counts a few clusters more than the FAT holds and
    // lets the free count wrap when the volume fills up; fsck reports
    // exactly that on top of the unclosed-file state (firmware/docs/hil.md,
    // "Known issues").
    let known_full_volume = |p: &str| p.starts_with("Cluster ") && p.contains(" out of range ");
    assert!(
        fsck.problems()
            .iter()
            .all(|p| qemu::is_unclosed_file_state(p) || known_full_volume(p)),
        "{}",
        fsck.text
    );
    assert_alerted(&out);
}

#[test]
fn imu_that_stops_answering_is_flagged_and_counted() {
    let scenario = Scenario {
        imu_dead_from_ms: Some(5000),
        ..Scenario::ride(FRAMES)
    };
    let (out, logs) = run("imu_dead", scenario, |_| Ok(()));
    let log = &logs[0];
    assert_eq!(log.frames.len(), FRAMES as usize);
    let dead: Vec<_> = log
        .frames
        .iter()
        .filter(|f| f.status.has(FrameStatus::IMU_FAULT))
        .collect();
    assert!(dead
        .iter()
        .all(|f| f.t_us >= 5_000_000 && f.status.has(FrameStatus::IMU_STALE)));
    // Every frame from the first read after 5 s: the driver sees the
    // floating bus at once, not only once the stuck check would.
    let after = log.frames.iter().filter(|f| f.t_us >= 5_000_000).count();
    assert!(
        dead.len().abs_diff(after) <= 1,
        "{} frames flagged, {after} after 5 s",
        dead.len()
    );
    let counted = imu_faults_counted(log);
    // Counts are recorded once a second: the last second may be pending.
    assert!(
        counted + 100 >= dead.len() as u64 && counted <= dead.len() as u64,
        "{counted} counted"
    );
    assert_alerted(&out);
}

#[test]
fn gps_garbage_is_a_fault_and_fixes_resume() {
    let scenario = Scenario {
        gps_garbage_ms: Some((5000, 10_000)),
        ..Scenario::ride(FRAMES)
    };
    let (out, logs) = run("gps_garbage", scenario, |_| Ok(()));
    let log = &logs[0];
    assert_eq!(log.frames.len(), FRAMES as usize);
    assert!(log.faults.iter().any(|f| f.source == FaultSource::Gps));
    let in_window = log
        .fixes
        .iter()
        .filter(|f| (5_300_000..10_000_000).contains(&f.t_us) && f.lat_e7.is_some())
        .count();
    let after = log
        .fixes
        .iter()
        .filter(|f| f.t_us >= 11_000_000 && f.lat_e7.is_some())
        .count();
    assert_eq!(in_window, 0);
    assert!(after >= 40, "{after} fixes after the noise");
    assert_alerted(&out);
}

#[test]
fn imu_that_freezes_is_found_stuck_and_set_up_again() {
    // Data registers frozen from 5 to 8 s: after 50 identical samples
    // (0.5 s) the frames are flagged, the port resets the sensor (at most
    // once a second) and live values return after the freeze.
    let scenario = Scenario {
        imu_stuck_ms: Some((5000, 8000)),
        ..Scenario::ride(FRAMES)
    };
    let (out, logs) = run("imu_stuck", scenario, |_| Ok(()));
    let log = &logs[0];
    let stuck = wobble_core::imu::ImuConfig::DEFAULT.stuck_samples;
    let found_us = 5_000_000 + u64::from(stuck) * 10_000;
    for f in &log.frames {
        let flagged = f.status.has(FrameStatus::IMU_FAULT);
        if f.t_us < found_us - 20_000 || f.t_us >= 8_000_000 + 1_100_000 {
            assert!(!flagged, "frame at {} µs flagged", f.t_us);
        } else if (found_us..8_000_000).contains(&f.t_us) {
            assert!(flagged, "frame at {} µs not flagged", f.t_us);
        }
    }
    let counted = imu_faults_counted(log);
    let flagged = log
        .frames
        .iter()
        .filter(|f| f.status.has(FrameStatus::IMU_FAULT))
        .count() as u64;
    assert!(
        counted >= 1 && counted <= flagged,
        "{counted} counted, {flagged} flagged"
    );
    assert_alerted(&out);
}

#[test]
fn open_steering_wiper_is_saturated_not_an_angle() {
    // The wiper lifts from 3 to 4 s: the ADC reads full scale, every frame
    // in the window is flagged saturated, none outside it.
    let scenario = Scenario {
        steer_open_ms: Some((3000, 4000)),
        ..Scenario::ride(FRAMES)
    };
    let (out, logs) = run("steer_open", scenario, |_| Ok(()));
    let log = &logs[0];
    for f in &log.frames {
        let saturated = f.status.has(FrameStatus::STEER_SATURATED);
        assert_eq!(
            saturated,
            (3_000_000..4_000_000).contains(&f.t_us),
            "frame at {} µs",
            f.t_us
        );
    }
    assert_alerted(&out);
}
