//! The board's GPS task (`app::gps::run_link`) through a ride, in virtual
//! time, over the simulated UART of `gnss_support::link`: the real bring-up
//! and the real GPS path. A receiver that resets to its power-up state
//! (9600 baud, 1 Hz) mid-ride is found and configured again within a few
//! seconds; a fix is stamped with the time its first sentence began,
//! back-dated at the baud in force.

mod gnss_support;

use embassy_time::{Duration, Instant};
use gnss_support::link::{drive, link_to, SimLink};
use gnss_support::{Family, Receiver};
use wobble_core::app::gps::{run_link, LOSS_TIMEOUT_US};
use wobble_core::channels::{RecordQueue, SharedStatus};
use wobble_core::drivers::gnss_bringup::{Step, FAULT_RECEIVER_LOST, FAULT_SETUP_UNCONFIRMED};
use wobble_core::drivers::gnss_setup::TARGET_BAUD;
use wobble_core::format::{FaultSource, GpsFix, Record};

/// What the task queued, in order, with the time it was taken off.
struct Ride {
    fixes: Vec<GpsFix>,
    /// GPS fault records: (time, code).
    faults: Vec<(u64, u8)>,
    /// When each bring-up ended (its `Done` step was logged).
    done: Vec<Instant>,
}

/// Runs the GPS task on `link` for `secs` of virtual time, calling
/// `at_ms(ms)` each millisecond, and collects what it queued.
fn ride(link: &mut SimLink, secs: u64) -> Ride {
    let queue = RecordQueue::new();
    let shared = SharedStatus::new();
    let start = Instant::now();
    let mut ride = Ride {
        fixes: Vec::new(),
        faults: Vec::new(),
        done: Vec::new(),
    };
    let mut done = Vec::new();
    let mut on_step = |step: &Step| {
        if matches!(step, Step::Done(_)) {
            done.push(Instant::now());
        }
    };
    let mut drain = || {
        while let Some(rec) = queue.try_pop() {
            match rec {
                Record::Gps(fix) => ride.fixes.push(fix),
                Record::Fault(f) if f.source == FaultSource::Gps => {
                    ride.faults.push((f.t_us, f.code));
                }
                _ => {}
            }
        }
        if Instant::now().duration_since(start) >= Duration::from_secs(secs) {
            shared.request_stop();
        }
    };
    drive(
        run_link(link, &queue, &shared, &mut on_step),
        Duration::from_secs(secs + 30),
        &mut drain,
    );
    drain();
    ride.done = done;
    ride
}

/// Every fix is stamped within `tolerance_us` of a `$` that came over
/// the line (the start of its epoch's first sentence).
fn assert_stamped_at_sentence_starts(fixes: &[GpsFix], link: &SimLink, tolerance_us: u64) {
    assert!(!fixes.is_empty());
    for fix in fixes {
        let nearest = link
            .dollars
            .iter()
            .map(|d| d.as_micros().abs_diff(fix.t_us))
            .min()
            .unwrap_or(u64::MAX);
        assert!(
            nearest <= tolerance_us,
            "fix at {} us is {nearest} us from the nearest sentence start",
            fix.t_us
        );
    }
}

#[test]
fn a_receiver_reset_to_9600_mid_ride_is_back_at_20_hz_within_a_few_seconds() {
    let (_clock, mut link) = link_to(Receiver::new(Family::Mtk, 9_600));
    // Brought up (about 4 s), then 10 s of riding, then it browns out.
    let reset_at = Instant::now() + Duration::from_secs(14);
    link.reset = Some((reset_at, Receiver::new(Family::Mtk, 9_600)));
    let ride = ride(&mut link, 40);

    // Brought up twice, at boot and after the loss, and configured again.
    assert_eq!(ride.done.len(), 2, "bring-ups: {:?}", ride.done);
    assert_eq!(
        (link.rx.baud, link.rx.rate_hz, link.rx.lean),
        (TARGET_BAUD, 20, true)
    );
    let lost: Vec<_> = ride
        .faults
        .iter()
        .filter(|f| f.1 == FAULT_RECEIVER_LOST)
        .collect();
    assert_eq!(lost.len(), 1, "faults: {:?}", ride.faults);
    // The reset takes effect at the start of the simulated line's next
    // window (within 1 s); the loss is declared after the timeout.
    let lost_us = lost[0].0;
    let reset_us = reset_at.as_micros();
    assert!(lost_us >= reset_us + LOSS_TIMEOUT_US, "lost at {lost_us}");
    assert!(lost_us <= reset_us + 1_000_000 + LOSS_TIMEOUT_US + 200_000);

    // Fixes at 20 Hz before the reset and again after the second bring-up.
    let before = ride.fixes.iter().filter(|f| f.t_us < reset_us).count();
    let resumed = ride
        .fixes
        .iter()
        .find(|f| f.t_us > lost_us)
        .expect("fixes after the loss")
        .t_us;
    let gap_s = (resumed - reset_us) as f64 / 1e6;
    // Loss timeout 3 s + probe at 9600 1.35 s + two command sets and the
    // 2.15 s check: back within 9 s of the reset (the line's window adds
    // up to 1 s).
    assert!(gap_s < 9.0, "GPS back {gap_s:.2} s after the reset");
    println!("FIGURES gps recovery: 20 Hz fixes again {gap_s:.2} s after the receiver reset to 9600 baud");
    let after = ride.fixes.iter().filter(|f| f.t_us > resumed).count();
    let end_us = ride.fixes.last().unwrap().t_us;
    let rate_after = after as f64 / ((end_us - resumed) as f64 / 1e6);
    assert!(before > 150, "{before} fixes before the reset");
    assert!(
        (19.0..=21.0).contains(&rate_after),
        "{rate_after:.1} Hz after"
    );
    // At 115 200 baud, through the loss: stamped within a character time
    // plus the 1 ms step of the test's clock.
    assert_stamped_at_sentence_starts(&ride.fixes, &link, 1_500);
}

#[test]
fn a_receiver_left_at_9600_has_its_fixes_back_dated_at_9600() {
    // Deaf to every command: logging goes on at its own 9600 baud, 1 Hz,
    // four sentences (about 280 ms on the wire) per epoch.
    let (_clock, mut link) = link_to(Receiver::new(Family::Deaf, 9_600));
    let ride = ride(&mut link, 40);
    assert_eq!(
        ride.faults.first().map(|f| f.1),
        Some(FAULT_SETUP_UNCONFIRMED)
    );
    assert_eq!(link.baud, 9_600);
    let logged: Vec<_> = ride
        .fixes
        .iter()
        .copied()
        .filter(|f| f.t_us > ride.done[0].as_micros())
        .collect();
    assert!(logged.len() >= 10, "{} fixes", logged.len());
    // One character time at 9600 is 1.04 ms; the UART's idle wake-up and
    // the test clock's step add up to 1.5 ms more.
    assert_stamped_at_sentence_starts(&logged, &link, 2_600);
    // A receiver that keeps talking is never taken as lost.
    assert!(!ride.faults.iter().any(|f| f.1 == FAULT_RECEIVER_LOST));
}

#[test]
fn a_receiver_never_heard_is_probed_again_after_the_loss_timeout() {
    // Unplugged at boot, plugged in 25 s later.
    let mut absent = Receiver::new(Family::Mtk, 9_600);
    absent.silent = true;
    let (_clock, mut link) = link_to(absent);
    let plugged = Instant::now() + Duration::from_secs(25);
    link.reset = Some((plugged, Receiver::new(Family::Mtk, 9_600)));
    let ride = ride(&mut link, 60);
    assert!(ride.done.len() >= 2);
    // Between bring-ups the link listens at the outcome's 9600.
    assert_eq!(link.rx.baud, TARGET_BAUD);
    let first = ride.fixes.first().expect("fixes once plugged in").t_us;
    let late_s = (first - plugged.as_micros()) as f64 / 1e6;
    // At worst a whole silent bring-up (about 17 s) and the loss timeout
    // are under way when it is plugged in, then its own bring-up.
    assert!(late_s < 30.0, "first fix {late_s:.1} s after plugging in");
}
