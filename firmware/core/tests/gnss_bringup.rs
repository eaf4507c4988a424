//! The GPS bring-up state machine against simulated receivers: MediaTek,
//! u-blox M8 (legacy UBX), u-blox M10 (CFG-VALSET only), one that obeys no
//! command, one still booting, one at a stored odd baud, one that cannot
//! do 20 Hz, a silent line and a line of noise. The simulated receiver
//! sends real NMEA sentences at its own baud and rate (limited by what the
//! baud can carry); bytes read at another baud arrive as garbage, and
//! commands sent at another baud are lost.

use proptest::prelude::*;
use wobble_core::drivers::gnss_bringup::{
    Bringup, CommandSet, Outcome, SentenceCounter, Step, FAULT_SETUP_SILENT, FAULT_SETUP_SLOW,
    FAULT_SETUP_UNCONFIRMED, PROBE_BAUDS, PROBE_ROUNDS,
};
use wobble_core::drivers::gnss_setup::TARGET_BAUD;

/// `$body*hh\r\n` (the set-up module's `nmea` holds only short commands).
fn nmea(body: &str) -> Vec<u8> {
    let checksum = body.bytes().fold(0u8, |acc, b| acc ^ b);
    format!("${body}*{checksum:02X}\r\n").into_bytes()
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Family {
    /// PMTK commands.
    Mtk,
    /// u-blox M8: legacy UBX CFG messages.
    UbloxM8,
    /// u-blox M10: CFG-VALSET only.
    UbloxM10,
    /// NMEA out, deaf to every command.
    Deaf,
}

#[derive(Clone, Debug)]
struct Receiver {
    family: Family,
    baud: u32,
    rate_hz: u32,
    max_rate_hz: u32,
    /// Only RMC and GGA (else also GSA and GSV, as out of the box).
    lean: bool,
    /// Listening windows during which it is still booting (silent).
    booting: u32,
    /// Noise instead of sentences, at every baud.
    noise: bool,
    silent: bool,
    /// Deterministic noise generator state.
    seed: u64,
}

impl Receiver {
    fn new(family: Family, baud: u32) -> Self {
        Self {
            family,
            baud,
            rate_hz: 1,
            max_rate_hz: 20,
            lean: false,
            booting: 0,
            noise: false,
            silent: false,
            seed: 0x9E37_79B9_7F4A_7C15,
        }
    }

    fn noise_byte(&mut self) -> u8 {
        self.seed ^= self.seed << 13;
        self.seed ^= self.seed >> 7;
        self.seed ^= self.seed << 17;
        (self.seed >> 24) as u8
    }

    /// One epoch's sentences.
    fn epoch(&self, k: u32) -> Vec<u8> {
        let t = format!("1232{:02}.{:02}", k / 20 % 60, k % 20 * 5);
        let mut out = nmea(&format!(
            "GPRMC,{t},A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W"
        ));
        out.extend(nmea(&format!(
            "GPGGA,{t},4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"
        )));
        if !self.lean {
            out.extend(nmea("GPGSA,A,3,04,05,,09,12,,,24,,,,,2.5,1.3,2.1"));
            out.extend(nmea(
                "GPGSV,2,1,08,01,40,083,46,02,17,308,41,12,07,344,39,14,22,228,45",
            ));
        }
        out
    }

    /// What the UART at `baud` receives during `for_us`.
    fn transmit(&mut self, baud: u32, for_us: u64) -> Vec<u8> {
        if self.silent {
            return Vec::new();
        }
        if self.booting > 0 {
            self.booting -= 1;
            return Vec::new();
        }
        let line_bytes_per_s = u64::from(self.baud / 10);
        let mut out = Vec::new();
        if self.noise {
            let n = (u64::from(baud / 10) * for_us / 1_000_000) as usize;
            return (0..n).map(|_| self.noise_byte()).collect();
        }
        // The rate is what the line can carry.
        let epoch_len = self.epoch(0).len() as u64;
        let rate = u64::from(self.rate_hz)
            .min(line_bytes_per_s / epoch_len)
            .max(1);
        let epochs = rate * for_us / 1_000_000;
        for k in 0..epochs {
            out.extend(self.epoch(k as u32));
        }
        if baud == self.baud {
            out
        } else {
            // Sampled at the wrong baud: as many bytes, none of them text.
            let n = out.len() * baud as usize / self.baud as usize;
            (0..n).map(|_| self.noise_byte() | 0x80).collect()
        }
    }

    /// Applies one command received at `baud`.
    fn receive(&mut self, baud: u32, cmd: &[u8]) {
        if baud != self.baud || self.silent || self.noise || self.booting > 0 {
            return;
        }
        let text = std::str::from_utf8(cmd).unwrap_or("");
        match self.family {
            Family::Mtk => {
                if let Some(b) = text.strip_prefix("$PMTK251,") {
                    self.baud = b.split('*').next().unwrap().parse().unwrap();
                } else if text.starts_with("$PMTK220,50*") {
                    self.rate_hz = 20.min(self.max_rate_hz);
                } else if text.starts_with("$PMTK314,0,1,0,1,0,0,") {
                    self.lean = true;
                }
            }
            Family::UbloxM8 => match (cmd.first(), cmd.get(2..4)) {
                (Some(0xB5), Some([0x06, 0x00])) => {
                    self.baud = u32::from_le_bytes(cmd[14..18].try_into().unwrap());
                }
                (Some(0xB5), Some([0x06, 0x08])) => {
                    let ms = u32::from(u16::from_le_bytes([cmd[6], cmd[7]]));
                    self.rate_hz = (1000 / ms).min(self.max_rate_hz);
                }
                // CFG-MSG for GSV off (the last of the GSA/GSV pair sent).
                (Some(0xB5), Some([0x06, 0x01])) if cmd[7] == 0x03 && cmd[8] == 0 => {
                    self.lean = true;
                }
                _ => {}
            },
            Family::UbloxM10 => {
                if cmd.first() == Some(&0xB5) && cmd.get(2..4) == Some(&[0x06, 0x8A]) {
                    // Rate (first item) and baud (last item), see gnss_setup.
                    let ms = u32::from(u16::from_le_bytes([cmd[14], cmd[15]]));
                    self.rate_hz = (1000 / ms).min(self.max_rate_hz);
                    self.lean = true;
                    let n = cmd.len();
                    self.baud = u32::from_le_bytes(cmd[n - 6..n - 2].try_into().unwrap());
                }
            }
            Family::Deaf => {}
        }
    }
}

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
