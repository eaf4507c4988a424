//! Bringing up the GPS receiver: find its baud rate, configure it, check
//! that it took the configuration, try the next command set if not, and
//! fall back to logging whatever it sends.
//!
//! A receiver may still be booting when the logger starts, may talk at
//! 9600 or 38 400 baud (or anything the last user stored), and may ignore
//! one dialect of set-up commands. Sending once, blind, risks a whole ride
//! without GPS, and every byte read at the wrong baud is a framing error.
//!
//! [`Bringup`] is a plain state machine: it says what to do next
//! ([`Step`]), the caller does it (switches the UART, sends commands,
//! listens for a while counting what arrives with a [`SentenceCounter`])
//! and reports back. So every path is tested on the host with constructed
//! byte streams, and the board only moves bytes (`app::gps_setup` drives
//! it over the `GpsLink` port).
//!
//! ```text
//! Probe: listen at 9600, 38 400, 57 600, 115 200 (up to PROBE_ROUNDS rounds) ─ valid NMEA? ─┐
//!   none at any baud: Done(silent, logging at 9600)                                        │
//! Configure (legacy, then VALSET): send at the found baud, listen at 115 200 <───────────────┘
//!   valid NMEA at 115 200 at 20 Hz: Done(configured)
//!   valid but slower: try VALSET too, then Done(configured, with the rate measured)
//!   none: next command set; none left: listen at the found baud again
//!     valid: Done(unconfigured, logging at the found baud)   none: back to Probe (once)
//! ```

use super::gnss_setup::{baud_commands, rate_commands, valset_command, Command, TARGET_BAUD};
use heapless::Vec;

use crate::gps::line::{LineAssembler, LineEvent};

/// Baud rates listened at, most likely first: nearly every receiver powers
/// up at 9600; u-blox M10 modules often at 38 400.
pub const PROBE_BAUDS: [u32; 4] = [9_600, 38_400, 57_600, TARGET_BAUD];
/// Listening time per baud while probing, µs: a 1 Hz receiver sends its
/// epoch's sentences once a second.
pub const PROBE_LISTEN_US: u64 = 1_200_000;
/// Rounds over [`PROBE_BAUDS`] before the receiver counts as silent (it
/// may take a few seconds to boot).
pub const PROBE_ROUNDS: u8 = 3;
/// Listening time after a set-up, µs: long enough to measure the rate.
pub const VERIFY_LISTEN_US: u64 = 2_000_000;
/// Valid sentences that prove a baud rate (one could be chance in noise:
/// a wrong baud gives a valid checksum once in 256 lines at best).
pub const MIN_VALID_SENTENCES: u32 = 2;
/// Wait after sending commands, µs, before listening: the receiver applies
/// a new baud rate or rate (u-blox: about 100 ms after CFG-PRT).
pub const SETTLE_US: u64 = 150_000;

/// GPS fault 10: no valid NMEA at any baud rate; logging at 9600 anyway.
/// Earlier firmware recorded it as 6, the code of
/// [`crate::gps::FAULT_OUT_OF_RANGE`] (FORMAT.md).
pub const FAULT_SETUP_SILENT: u8 = 10;
/// GPS fault 7: no command set was confirmed; logging at the receiver's
/// own baud and rate.
pub const FAULT_SETUP_UNCONFIRMED: u8 = 7;
/// GPS fault 8: configured, but sentences come at less than the 20 Hz
/// asked for (the receiver's own limit).
pub const FAULT_SETUP_SLOW: u8 = 8;

/// GPS fault 9: while logging, no valid sentence came for
/// `app::gps::LOSS_TIMEOUT_US` (a receiver that browned out or was
/// re-plugged, back at its stored baud): the bring-up runs again.
pub const FAULT_RECEIVER_LOST: u8 = 9;

/// Epochs per second that count as the 20 Hz asked for.
const MIN_RATE_HZ: u32 = 15;

/// What a listening window held.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Heard {
    /// NMEA sentences whose checksum matched.
    pub valid: u32,
    /// Lines dropped (bad checksum, framing): what a wrong baud gives.
    pub rejected: u32,
    /// RMC sentences (one per epoch when enabled).
    pub rmc: u32,
    /// GGA sentences (one per epoch when enabled).
    pub gga: u32,
}

/// Counts the sentences in a byte stream (a thin layer over the GPS path's
/// own line assembler, so "valid" means the same everywhere).
#[derive(Clone, Debug, Default)]
pub struct SentenceCounter {
    line: LineAssembler,
    heard: Heard,
}

impl SentenceCounter {
    /// Nothing heard yet.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Counts what `bytes` hold.
    pub fn feed(&mut self, bytes: &[u8]) {
        for &b in bytes {
            match self.line.push(b, 0) {
                Some(LineEvent::Valid { text, .. }) => {
                    let h = &mut self.heard;
                    h.valid += 1;
                    // `$ttRMC,...`: the talker is two letters.
                    match text.get(3..6) {
                        Some("RMC") => h.rmc += 1,
                        Some("GGA") => h.gga += 1,
                        _ => {}
                    }
                }
                Some(LineEvent::Rejected { .. }) => self.heard.rejected += 1,
                None => {}
            }
        }
    }

    /// What was heard so far.
    #[must_use]
    pub const fn heard(&self) -> Heard {
        self.heard
    }
}

/// A set of configuration commands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CommandSet {
    /// MediaTek PMTK and u-blox legacy CFG-PRT/RATE/MSG: baud switch.
    LegacyBaud,
    /// The rate and sentence part of the legacy set (sent at 115 200).
    LegacyRate,
    /// u-blox CFG-VALSET (M9/M10): everything in one message.
    Valset,
}

/// Most commands in one set.
pub const MAX_SET_LEN: usize = 9;

impl CommandSet {
    /// The commands, ready for the UART, in order.
    #[must_use]
    pub fn commands(self) -> Vec<Command, MAX_SET_LEN> {
        let mut out = Vec::new();
        let all: &[Command] = match self {
            Self::LegacyBaud => &baud_commands(),
            Self::LegacyRate => &rate_commands(),
            Self::Valset => &[valset_command()],
        };
        // The largest set is MAX_SET_LEN long.
        let _ = out.extend_from_slice(all);
        out
    }
}

/// What to do next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Step {
    /// Set the UART to `baud`, count what arrives for `for_us` (drop what
    /// was buffered before), then call [`Bringup::heard`].
    Listen {
        /// Baud rate.
        baud: u32,
        /// How long, µs.
        for_us: u64,
    },
    /// Set the UART to `baud`, send `set`, wait [`SETTLE_US`], then call
    /// [`Bringup::sent`].
    Send {
        /// Baud rate.
        baud: u32,
        /// What to send.
        set: CommandSet,
    },
    /// Finished: log at this baud rate from now on.
    Done(Outcome),
}

/// How the bring-up ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Outcome {
    /// The baud rate to log at.
    pub baud: u32,
    /// The baud rate the receiver was found at, if it was.
    pub found_baud: Option<u32>,
    /// The command set it took, if any.
    pub configured: Option<CommandSet>,
    /// Epochs per second heard at the end, from RMC or GGA.
    pub rate_hz: u32,
}

impl Outcome {
    /// The GPS fault to record for it, if any.
    #[must_use]
    pub const fn fault(&self) -> Option<u8> {
        match (self.found_baud, self.configured) {
            (None, _) => Some(FAULT_SETUP_SILENT),
            (Some(_), None) => Some(FAULT_SETUP_UNCONFIRMED),
            (Some(_), Some(_)) if self.rate_hz < MIN_RATE_HZ => Some(FAULT_SETUP_SLOW),
            _ => None,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    /// Listening at `PROBE_BAUDS[index]` in `round`.
    Probe { round: u8, index: usize },
    /// Sent `set` at `found`; next: its second part or the check.
    /// `earlier`: a set after which the receiver already talked at the
    /// target baud, but below 20 Hz.
    Sent {
        found: u32,
        set: CommandSet,
        earlier: Option<CommandSet>,
    },
    /// Listening at the target after `set`.
    Verify {
        found: u32,
        set: CommandSet,
        earlier: Option<CommandSet>,
    },
    /// Every set failed: listening at `found` again.
    Recheck { found: u32 },
    /// Finished.
    Done(Outcome),
}

/// The bring-up state machine (see the module docs).
#[derive(Clone, Debug)]
pub struct Bringup {
    state: State,
    /// Whether the probe has been restarted after a lost receiver.
    reprobed: bool,
}

impl Default for Bringup {
    fn default() -> Self {
        Self::new()
    }
}

/// Epochs per second in a window of `for_us` holding `heard`.
fn rate_hz(heard: Heard, for_us: u64) -> u32 {
    let epochs = u64::from(heard.rmc.max(heard.gga));
    u32::try_from(epochs * 1_000_000 / for_us.max(1)).unwrap_or(u32::MAX)
}

impl Bringup {
    /// Nothing done yet.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            state: State::Probe { round: 0, index: 0 },
            reprobed: false,
        }
    }

    /// The step to take now (the first one, or again after a report).
    #[must_use]
    pub fn step(&self) -> Step {
        match self.state {
            State::Probe { index, .. } => Step::Listen {
                baud: PROBE_BAUDS[index],
                for_us: PROBE_LISTEN_US,
            },
            State::Sent { found, set, .. } => Step::Send {
                baud: if set == CommandSet::LegacyRate {
                    TARGET_BAUD
                } else {
                    found
                },
                set,
            },
            State::Verify { .. } => Step::Listen {
                baud: TARGET_BAUD,
                for_us: VERIFY_LISTEN_US,
            },
            State::Recheck { found } => Step::Listen {
                baud: found,
                for_us: VERIFY_LISTEN_US,
            },
            State::Done(outcome) => Step::Done(outcome),
        }
    }

    /// The first command set to try once the receiver is found.
    const fn configure(found: u32) -> State {
        State::Sent {
            found,
            set: CommandSet::LegacyBaud,
            earlier: None,
        }
    }

    /// Reports what the last [`Step::Listen`] heard; returns the next step.
    pub fn heard(&mut self, heard: Heard) -> Step {
        let alive = heard.valid >= MIN_VALID_SENTENCES;
        self.state = match self.state {
            State::Probe { index, .. } if alive => Self::configure(PROBE_BAUDS[index]),
            State::Probe { round, index } if index + 1 < PROBE_BAUDS.len() => State::Probe {
                round,
                index: index + 1,
            },
            State::Probe { round, .. } if round + 1 < PROBE_ROUNDS => State::Probe {
                round: round + 1,
                index: 0,
            },
            State::Probe { .. } => State::Done(Outcome {
                baud: PROBE_BAUDS[0],
                found_baud: None,
                configured: None,
                rate_hz: 0,
            }),
            State::Verify {
                found,
                set,
                earlier,
            } => {
                let rate = rate_hz(heard, VERIFY_LISTEN_US);
                let done = |configured| {
                    State::Done(Outcome {
                        baud: TARGET_BAUD,
                        found_baud: Some(found),
                        configured: Some(configured),
                        rate_hz: rate,
                    })
                };
                match (alive, set) {
                    (true, _) if rate >= MIN_RATE_HZ => done(set),
                    (true, CommandSet::Valset) => done(earlier.unwrap_or(set)),
                    // At the target baud already, but slow: perhaps it is
                    // a receiver that only takes the other set.
                    (true, _) => State::Sent {
                        found: TARGET_BAUD,
                        set: CommandSet::Valset,
                        earlier: Some(set),
                    },
                    (false, CommandSet::LegacyBaud | CommandSet::LegacyRate) => State::Sent {
                        found,
                        set: CommandSet::Valset,
                        earlier: None,
                    },
                    (false, CommandSet::Valset) => State::Recheck { found },
                }
            }
            State::Recheck { found } if alive => State::Done(Outcome {
                baud: found,
                found_baud: Some(found),
                configured: None,
                rate_hz: rate_hz(heard, VERIFY_LISTEN_US),
            }),
            State::Recheck { .. } if !self.reprobed => {
                self.reprobed = true;
                State::Probe { round: 0, index: 0 }
            }
            State::Recheck { found } => State::Done(Outcome {
                baud: found,
                found_baud: Some(found),
                configured: None,
                rate_hz: 0,
            }),
            // A report that does not fit the step: repeat the step.
            other @ (State::Sent { .. } | State::Done(_)) => other,
        };
        self.step()
    }

    /// Reports that the last [`Step::Send`] went out; returns the next step.
    pub fn sent(&mut self) -> Step {
        self.state = match self.state {
            State::Sent {
                found,
                set: CommandSet::LegacyBaud,
                earlier,
            } => State::Sent {
                found,
                set: CommandSet::LegacyRate,
                earlier,
            },
            State::Sent {
                found,
                set,
                earlier,
            } => State::Verify {
                found,
                set,
                earlier,
            },
            other => other,
        };
        self.step()
    }
}
