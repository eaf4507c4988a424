//! The async GPS bring-up runner (`app::gps_setup::run`) over a simulated
//! UART in virtual time: the receiver's bytes arrive at the line's pace, a
//! baud switch loses what was in flight, commands take their time on the
//! wire. The state machine's decisions are tested in `gnss_bringup.rs`;
//! here, that the runner carries them out on a link: baud switches before
//! each step, commands sent whole and in order, the settling time skipped,
//! the port read at least every `IDLE_POLL_MS` while listening and well
//! within a watchdog round while sending (the GPS task's heartbeat),
//! and the whole bring-up bounded in time and in log lines.

mod gnss_support;

use embassy_time::{Duration, Instant};
use gnss_support::link::{drive, link_to, SimLink};
use gnss_support::{Family, Receiver};
use wobble_core::app::gps::IDLE_POLL_MS;
use wobble_core::app::gps_setup::run;
use wobble_core::drivers::gnss_bringup::{
    CommandSet, Outcome, Step, FAULT_SETUP_SILENT, FAULT_SETUP_UNCONFIRMED, SETTLE_US,
};
use wobble_core::drivers::gnss_setup::TARGET_BAUD;
use wobble_core::watchdog::ROUND_US;

/// Runs the bring-up on `link` to its end in virtual time; returns the
/// outcome, the steps logged and the time taken. The link is left at the
/// outcome's baud.
fn bring_up(link: &mut SimLink) -> (Outcome, Vec<Step>, Duration) {
    let mut steps = Vec::new();
    let start = Instant::now();
    let outcome = {
        let mut log = |step: &Step| steps.push(*step);
        drive(run(link, &mut log), Duration::from_secs(120), &mut || {})
    };
    assert_eq!(link.baud, outcome.baud, "link and outcome disagree");
    assert_eq!(link.switches.last(), Some(&outcome.baud));
    (outcome, steps, Instant::now().duration_since(start))
}

/// The baud each Listen or Send step asked for, in order.
fn asked_bauds(steps: &[Step]) -> Vec<u32> {
    steps
        .iter()
        .filter_map(|step| match *step {
            Step::Listen { baud, .. } | Step::Send { baud, .. } => Some(baud),
            Step::Done(_) => None,
        })
        .collect()
}

#[test]
fn a_mediatek_at_9600_is_brought_to_115200_at_20_hz_on_the_link() {
    let (_clock, mut link) = link_to(Receiver::new(Family::Mtk, 9_600));
    let (outcome, steps, took) = bring_up(&mut link);
    assert_eq!(outcome.found_baud, Some(9_600));
    assert_eq!(outcome.configured, Some(CommandSet::LegacyRate));
    assert_eq!((outcome.baud, outcome.rate_hz), (TARGET_BAUD, 20));
    assert_eq!(outcome.fault(), None);
    assert_eq!(
        (link.rx.baud, link.rx.rate_hz, link.rx.lean),
        (TARGET_BAUD, 20, true)
    );
    // The UART is switched before every step, to the step's baud, and
    // at the end to the outcome's.
    assert_eq!(
        link.switches,
        [asked_bauds(&steps), vec![outcome.baud]].concat()
    );
    assert_eq!(steps.last(), Some(&Step::Done(outcome)));
    // Each set went out whole, in order, at the baud its step named.
    let mut expected = Vec::new();
    for step in &steps {
        if let Step::Send { baud, set } = *step {
            expected.extend(set.commands().iter().map(|c| (baud, c.to_vec())));
        }
    }
    assert_eq!(link.sent, expected);
    assert!(took < Duration::from_secs(10), "took {took}");
    // Sending a set and settling is the longest time without a read (the
    // legacy baud set at 9600 plus the settling time: about 0.37 s); the
    // watchdog wants a heartbeat every round, well within that.
    assert!(
        link.max_read_gap < Duration::from_micros(ROUND_US / 2),
        "reads {} apart",
        link.max_read_gap
    );
}

#[test]
fn a_ublox_m10_at_38400_is_configured_with_valset_on_the_link() {
    let (_clock, mut link) = link_to(Receiver::new(Family::UbloxM10, 38_400));
    let (outcome, steps, _) = bring_up(&mut link);
    assert_eq!(outcome.found_baud, Some(38_400));
    assert_eq!(outcome.configured, Some(CommandSet::Valset));
    assert_eq!((outcome.baud, outcome.rate_hz), (TARGET_BAUD, 20));
    assert_eq!(
        link.switches,
        [asked_bauds(&steps), vec![TARGET_BAUD]].concat()
    );
    // The legacy set went first and changed nothing: VALSET did it.
    let sets: Vec<_> = steps
        .iter()
        .filter_map(|s| match *s {
            Step::Send { set, .. } => Some(set),
            _ => None,
        })
        .collect();
    assert_eq!(sets.first(), Some(&CommandSet::LegacyBaud));
    assert_eq!(sets.last(), Some(&CommandSet::Valset));
}

#[test]
fn a_deaf_receiver_is_left_at_its_baud_after_a_bounded_bring_up() {
    let (_clock, mut link) = link_to(Receiver::new(Family::Deaf, 9_600));
    let (outcome, steps, took) = bring_up(&mut link);
    assert_eq!((outcome.baud, outcome.configured), (9_600, None));
    assert_eq!(outcome.fault(), Some(FAULT_SETUP_UNCONFIRMED));
    assert!(steps.len() < 40, "{} log lines", steps.len());
    assert!(took < Duration::from_secs(30), "took {took}");
}

#[test]
fn a_silent_line_ends_with_the_link_at_9600_with_reads_all_along() {
    let mut rx = Receiver::new(Family::Mtk, 9_600);
    rx.silent = true;
    let (_clock, mut link) = link_to(rx);
    let (outcome, steps, took) = bring_up(&mut link);
    assert_eq!((outcome.found_baud, outcome.baud), (None, 9_600));
    assert_eq!(outcome.fault(), Some(FAULT_SETUP_SILENT));
    // The last probe listened at 115 200; the UART is back at 9600.
    assert_eq!(
        &link.switches[link.switches.len() - 2..],
        [TARGET_BAUD, 9_600]
    );
    // Listening plus settling per probe, nothing more.
    let listening: u64 = steps
        .iter()
        .map(|s| match *s {
            Step::Listen { for_us, .. } => for_us + SETTLE_US,
            _ => 0,
        })
        .sum();
    let slack = Duration::from_millis(steps.len() as u64 * 10);
    assert!(took >= Duration::from_micros(listening), "took {took}");
    assert!(
        took <= Duration::from_micros(listening) + slack,
        "took {took}"
    );
    // Nothing arrives, yet the port is read every poll period.
    assert!(link.max_read_gap <= Duration::from_millis(IDLE_POLL_MS));
}

#[test]
fn a_receiver_already_at_115200_is_found_after_garbage_at_the_lower_bauds() {
    // A receiver already configured: at 115 200 and 20 Hz from the start.
    let mut rx = Receiver::new(Family::UbloxM8, TARGET_BAUD);
    rx.rate_hz = 20;
    let (_clock, mut link) = link_to(rx);
    let (outcome, steps, _) = bring_up(&mut link);
    // Found at 115 200 only after the lower bauds heard garbage.
    assert_eq!(outcome.found_baud, Some(TARGET_BAUD));
    assert_eq!(outcome.rate_hz, 20);
    assert_eq!(
        &asked_bauds(&steps)[..4],
        &[9_600, 38_400, 57_600, TARGET_BAUD]
    );
}
