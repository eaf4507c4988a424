//! The GPS bring-up state machine against simulated receivers: MediaTek,
//! u-blox M8 (legacy UBX), u-blox M10 (CFG-VALSET only), one that obeys no
//! command, one still booting, one at a stored odd baud, one that cannot
//! do 20 Hz, a silent line and a line of noise. The simulated receiver
//! sends real NMEA sentences at its own baud and rate (limited by what the
//! baud can carry); bytes read at another baud arrive as garbage, and
//! commands sent at another baud are lost.

mod gnss_support;

use gnss_support::{Family, Receiver};
use proptest::prelude::*;
use wobble_core::drivers::gnss_bringup::{
    Bringup, CommandSet, Heard, Outcome, SentenceCounter, Step, FAULT_SETUP_SILENT,
    FAULT_SETUP_SLOW, FAULT_SETUP_UNCONFIRMED, PROBE_BAUDS, PROBE_LISTEN_US, PROBE_ROUNDS,
    VERIFY_LISTEN_US,
};
use wobble_core::drivers::gnss_setup::TARGET_BAUD;

/// Runs the bring-up against `rx`; returns the outcome and the listening
/// time spent, µs.
fn bring_up(rx: &mut Receiver) -> (Outcome, u64) {
    let mut setup = Bringup::new();
    let mut step = setup.step();
    let mut listened_us = 0;
    for _ in 0..100 {
        step = match step {
            Step::Listen { baud, for_us } => {
                let mut counter = SentenceCounter::new();
                // In UART-sized chunks, as the DMA ring hands them over.
                for chunk in rx.transmit(baud, for_us).chunks(37) {
                    counter.feed(chunk);
                }
                listened_us += for_us;
                setup.heard(counter.heard())
            }
            Step::Send { baud, set } => {
                for cmd in set.commands() {
                    rx.receive(baud, &cmd);
                }
                setup.sent()
            }
            Step::Done(outcome) => return (outcome, listened_us),
        };
    }
    panic!("bring-up did not finish: {step:?}");
}

#[test]
fn a_mediatek_receiver_at_9600_is_configured_with_pmtk() {
    let mut rx = Receiver::new(Family::Mtk, 9_600);
    let (outcome, _) = bring_up(&mut rx);
    assert_eq!(outcome.found_baud, Some(9_600));
    assert_eq!(outcome.baud, TARGET_BAUD);
    assert_eq!(outcome.configured, Some(CommandSet::LegacyRate));
    assert_eq!(outcome.rate_hz, 20);
    assert_eq!(outcome.fault(), None);
    assert_eq!((rx.baud, rx.rate_hz, rx.lean), (TARGET_BAUD, 20, true));
}

#[test]
fn a_ublox_m8_is_configured_with_legacy_ubx() {
    let mut rx = Receiver::new(Family::UbloxM8, 9_600);
    let (outcome, _) = bring_up(&mut rx);
    assert_eq!(outcome.configured, Some(CommandSet::LegacyRate));
    assert_eq!((outcome.baud, outcome.rate_hz), (TARGET_BAUD, 20));
    assert!(rx.lean);
}

#[test]
fn a_ublox_m10_at_38400_ignores_legacy_and_takes_valset() {
    let mut rx = Receiver::new(Family::UbloxM10, 38_400);
    let (outcome, _) = bring_up(&mut rx);
    assert_eq!(outcome.found_baud, Some(38_400));
    assert_eq!(outcome.configured, Some(CommandSet::Valset));
    assert_eq!((outcome.baud, outcome.rate_hz), (TARGET_BAUD, 20));
    assert_eq!(outcome.fault(), None);
}

#[test]
fn a_ublox_m10_already_at_115200_gets_valset_after_legacy_changed_nothing() {
    let mut rx = Receiver::new(Family::UbloxM10, TARGET_BAUD);
    let (outcome, _) = bring_up(&mut rx);
    assert_eq!(outcome.configured, Some(CommandSet::Valset));
    assert_eq!(outcome.rate_hz, 20);
}

#[test]
fn a_slow_mediatek_keeps_the_set_that_configured_it() {
    let mut rx = Receiver::new(Family::Mtk, 9_600);
    rx.max_rate_hz = 10;
    let (outcome, _) = bring_up(&mut rx);
    assert_eq!(outcome.configured, Some(CommandSet::LegacyRate));
}

#[test]
fn a_receiver_left_at_57600_is_found_there() {
    let mut rx = Receiver::new(Family::UbloxM8, 57_600);
    let (outcome, _) = bring_up(&mut rx);
    assert_eq!(outcome.found_baud, Some(57_600));
    assert_eq!(outcome.baud, TARGET_BAUD);
}

#[test]
fn a_booting_receiver_is_found_on_a_later_round() {
    let mut rx = Receiver::new(Family::Mtk, 9_600);
    rx.booting = PROBE_BAUDS.len() as u32 + 1;
    let (outcome, _) = bring_up(&mut rx);
    assert_eq!(outcome.found_baud, Some(9_600));
    assert_eq!(outcome.rate_hz, 20);
}

#[test]
fn a_deaf_receiver_is_logged_at_its_own_baud_and_rate() {
    let mut rx = Receiver::new(Family::Deaf, 9_600);
    let (outcome, _) = bring_up(&mut rx);
    assert_eq!(outcome.baud, 9_600);
    assert_eq!(outcome.configured, None);
    assert_eq!(outcome.rate_hz, 1);
    assert_eq!(outcome.fault(), Some(FAULT_SETUP_UNCONFIRMED));
}

#[test]
fn a_receiver_that_cannot_do_20_hz_is_configured_and_flagged() {
    let mut rx = Receiver::new(Family::Mtk, 9_600);
    rx.max_rate_hz = 10;
    let (outcome, _) = bring_up(&mut rx);
    assert_eq!((outcome.baud, outcome.rate_hz), (TARGET_BAUD, 10));
    assert_eq!(outcome.fault(), Some(FAULT_SETUP_SLOW));
}

#[test]
fn no_answer_gives_up_after_bounded_rounds_at_9600() {
    let mut rx = Receiver::new(Family::Mtk, 9_600);
    rx.silent = true;
    let (outcome, listened_us) = bring_up(&mut rx);
    assert_eq!(outcome.found_baud, None);
    assert_eq!(outcome.baud, 9_600);
    assert_eq!(outcome.fault(), Some(FAULT_SETUP_SILENT));
    let rounds = u64::from(PROBE_ROUNDS) * PROBE_BAUDS.len() as u64;
    assert_eq!(listened_us, rounds * 1_200_000);
}

#[test]
fn noise_at_every_baud_is_no_receiver() {
    let mut rx = Receiver::new(Family::Mtk, 9_600);
    rx.noise = true;
    let (outcome, _) = bring_up(&mut rx);
    assert_eq!(outcome.found_baud, None);
    assert_eq!(outcome.fault(), Some(FAULT_SETUP_SILENT));
}

#[test]
fn the_counter_sees_rmc_gga_and_rejects_broken_lines() {
    let rx = Receiver::new(Family::Mtk, 9_600);
    let mut bytes = rx.epoch(0);
    bytes.extend(b"$GPRMC,broken*00\r\n");
    let mut counter = SentenceCounter::new();
    counter.feed(&bytes);
    let heard = counter.heard();
    assert_eq!(
        (heard.valid, heard.rmc, heard.gga, heard.rejected),
        (4, 1, 1, 1)
    );
}

fn arb_receiver() -> impl Strategy<Value = Receiver> {
    (
        prop_oneof![
            Just(Family::Mtk),
            Just(Family::UbloxM8),
            Just(Family::UbloxM10),
            Just(Family::Deaf)
        ],
        prop::sample::select(PROBE_BAUDS.to_vec()),
        // Talking within the first two of the three probe rounds.
        0u32..8,
        prop::sample::select(vec![1u32, 5, 10, 20]),
        any::<bool>(),
    )
        .prop_map(|(family, baud, booting, max_rate_hz, silent)| {
            let mut rx = Receiver::new(family, baud);
            rx.booting = booting;
            rx.max_rate_hz = max_rate_hz;
            rx.silent = silent;
            rx
        })
}

proptest! {
    /// Whatever the receiver, the bring-up ends, and a receiver that talks
    /// is logged at the baud it talks at, its fault saying why not 20 Hz.
    #[test]
    fn the_logger_ends_up_where_the_receiver_talks(mut rx in arb_receiver()) {
        let (outcome, listened_us) = bring_up(&mut rx);
        // Bounded: at most two probes and the set-up checks.
        prop_assert!(listened_us <= 2 * 14_400_000 + 3 * 2_000_000);
        if rx.silent {
            prop_assert_eq!(outcome.fault(), Some(FAULT_SETUP_SILENT));
        } else {
            prop_assert_eq!(outcome.baud, rx.baud);
            prop_assert!(outcome.rate_hz >= 1);
            let full_rate = outcome.rate_hz >= 15;
            prop_assert_eq!(outcome.fault().is_none(), outcome.configured.is_some() && full_rate);
        }
    }
}

/// Drives the bring-up with `answer` deciding what each listening window
/// holds; returns the outcome and the listening windows' bauds and lengths.
fn drive(answer: impl Fn(u32, u64) -> Heard) -> (Outcome, Vec<(u32, u64)>) {
    let mut setup = Bringup::new();
    let mut step = setup.step();
    let mut listens = Vec::new();
    for _ in 0..200 {
        step = match step {
            Step::Listen { baud, for_us } => {
                listens.push((baud, for_us));
                setup.heard(answer(baud, for_us))
            }
            Step::Send { .. } => setup.sent(),
            Step::Done(outcome) => return (outcome, listens),
        };
    }
    panic!("bring-up did not finish: {step:?}");
}

/// A receiver that answers every probe at 9600 but falls silent after
/// every command set: once the sets have failed and the recheck at 9600
/// hears nothing, the probe starts over once; after the second failure the
/// bring-up ends unconfirmed at the baud the receiver was found at.
#[test]
fn a_receiver_lost_after_its_commands_is_probed_again_once() {
    let talking = Heard {
        valid: 20,
        rmc: 10,
        ..Heard::default()
    };
    let (outcome, listens) = drive(|baud, for_us| {
        if baud == PROBE_BAUDS[0] && for_us == PROBE_LISTEN_US {
            talking
        } else {
            Heard::default()
        }
    });
    let probes = listens.iter().filter(|l| l.1 == PROBE_LISTEN_US).count();
    let rechecks = listens
        .iter()
        .filter(|&&l| l == (PROBE_BAUDS[0], VERIFY_LISTEN_US))
        .count();
    assert_eq!((probes, rechecks), (2, 2), "{listens:?}");
    assert_eq!(outcome.found_baud, Some(PROBE_BAUDS[0]));
    assert_eq!(outcome.fault(), Some(FAULT_SETUP_UNCONFIRMED));
}

/// 15 epochs per second count as the 20 Hz asked for (the bring-up's
/// `MIN_RATE_HZ`, the rate its verification accepts): not slow; one fewer
/// is.
#[test]
fn fifteen_hz_is_not_slow() {
    let outcome = |rate_hz| Outcome {
        baud: TARGET_BAUD,
        found_baud: Some(9_600),
        configured: Some(CommandSet::Valset),
        rate_hz,
    };
    assert_eq!(outcome(15).fault(), None);
    assert_eq!(outcome(14).fault(), Some(FAULT_SETUP_SLOW));
}
