//! The GPS path: UART bytes -> NMEA lines -> merged fixes, UTC sync pairs and
//! counted faults.
//!
//! ```text
//! bytes ──> line::LineAssembler ──> sentence::parse ──> epoch::EpochMerger ──> GpsFix
//!  (any chunking)  (checksum, resync)   (the `nmea` crate)   (one fix per epoch)  UtcSync
//!                         └──────────────────┴──> faults ──> Fault (FaultSource::Gps)
//! ```
//!
//! [`GpsReceiver`] owns the whole path. It never blocks, never allocates and
//! holds one line and one epoch; the firmware's UART task feeds it whatever
//! the DMA delivered, and the `wobblog nmea` command feeds it a capture with
//! a synthetic clock, through exactly the same code.
//!
//! Local timestamps: a fix carries the local time at which the first byte
//! (`$`) of its epoch's first sentence arrived. When bytes come in chunks,
//! each byte is back-dated from the chunk's arrival time by the UART character
//! time ([`GpsConfig::baud`], 10 bits per character).

pub mod epoch;
pub mod line;
pub mod sentence;

use crate::faults::FaultCounter;
use crate::format::{Fault, FaultSource, FixMode, GpsFix, UtcSync};
use epoch::EpochMerger;
use line::{LineAssembler, LineError, LineEvent};
use sentence::Sentence;

// Fault codes of `FaultSource::Gps` records. FORMAT.md lists the same codes.
// Proprietary sentences (`$P...`) never count as faults: NMEA leaves their
// length and checksum to the vendor, and they are skipped unparsed anyway.

/// GPS fault 1: a line's `*hh` checksum did not match its contents, or the
/// checksum digits themselves were corrupt.
pub const FAULT_CHECKSUM: u8 = 1;
/// GPS fault 2: a line ended without a `*hh` checksum field (seen from
/// receivers in an error state, e.g. SkyTraq's `$STI,IC,error=4`).
pub const FAULT_NO_CHECKSUM: u8 = 2;
/// GPS fault 3: no line end within 102 bytes of the `$` (`line::MAX_LINE`);
/// the line was dropped.
pub const FAULT_OVERLONG: u8 = 3;
/// GPS fault 4: a line was cut short by a new `$`, or contained a control or
/// non-ASCII byte: bytes were lost or corrupted on the wire (baud mismatch,
/// UART overrun, noise).
pub const FAULT_FRAMING: u8 = 4;
/// GPS fault 5: a sentence of a type the fix is built from (RMC, GGA, GLL,
/// VTG, GSA, ZDA) had a valid checksum but could not be parsed.
pub const FAULT_UNPARSEABLE: u8 = 5;
/// GPS fault 6: a sentence of such a type parsed, but a field is outside
/// what a receiver can mean (position off the globe, minutes of 60 or more,
/// speed over 514 m/s, altitude outside -500 m to 18 km, more than 99
/// satellites): none of it is used. Also counted, with the rest of the fix
/// kept: an HDOP the record cannot hold (over 25.4 or negative; left
/// unknown, never clamped), and a leap second (23:59:60) on a day that
/// cannot end with one (the fix goes without its UTC).
pub const FAULT_OUT_OF_RANGE: u8 = 6;
/// Number of GPS fault codes (`1..=FAULT_CODES`).
pub const FAULT_CODES: usize = 6;

/// A short name for GPS fault `code`, for reports.
#[must_use]
pub const fn fault_name(code: u8) -> Option<&'static str> {
    Some(match code {
        FAULT_CHECKSUM => "checksum errors",
        FAULT_NO_CHECKSUM => "lines without checksum",
        FAULT_OVERLONG => "overlong lines",
        FAULT_FRAMING => "broken lines (lost or corrupt bytes)",
        FAULT_UNPARSEABLE => "unparseable sentences",
        FAULT_OUT_OF_RANGE => "sentences with fields out of range",
        _ => return None,
    })
}

/// Configuration of the GPS path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GpsConfig {
    /// UART baud rate, for back-dating the bytes of a chunk (8N1: 10 bits
    /// per character). `0` disables back-dating.
    pub baud: u32,
    /// An epoch still open this long after its first sentence began is
    /// emitted as it is. Must exceed the time a receiver takes to send one
    /// epoch's burst: at 4800 baud a 1 Hz burst takes up to about 0.9 s.
    pub epoch_timeout_us: u64,
    /// A `UtcSync` pair is produced with the first fix that has a valid UTC
    /// time, then with the first such fix after each interval.
    pub utc_sync_interval_us: u64,
    /// Each fault code is recorded at most once per interval (with a count).
    pub fault_interval_us: u64,
}

impl Default for GpsConfig {
    fn default() -> Self {
        Self {
            baud: 115_200,
            epoch_timeout_us: 1_500_000,
            utc_sync_interval_us: 10_000_000,
            fault_interval_us: 1_000_000,
        }
    }
}

/// Something the GPS path produced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GpsEvent {
    /// One merged epoch.
    Fix(GpsFix),
    /// A local time / UTC pair.
    UtcSync(UtcSync),
    /// Counted faults (codes `FAULT_*` of this module).
    Fault(Fault),
}

/// Counters since boot, for diagnostics.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GpsStats {
    /// Lines with a valid checksum.
    pub lines: u32,
    /// Valid lines skipped as not used (GSV, TXT, proprietary...).
    pub ignored: u32,
    /// Proprietary lines dropped for their length or missing checksum, which
    /// are not faults.
    pub proprietary_rejected: u32,
    /// Fixes emitted.
    pub fixes: u32,
    /// Faults by code: `faults[code - 1]`.
    pub faults: [u32; FAULT_CODES],
}

/// The GPS path (see the module docs).
#[derive(Clone, Debug)]
pub struct GpsReceiver {
    config: GpsConfig,
    line: LineAssembler,
    epoch: EpochMerger,
    faults: FaultCounter<FAULT_CODES>,
    last_sync_us: Option<u64>,
    stats: GpsStats,
}

impl GpsReceiver {
    /// A receiver waiting for its first byte.
    #[must_use]
    pub const fn new(config: GpsConfig) -> Self {
        Self {
            config,
            line: LineAssembler::new(),
            epoch: EpochMerger::new(config.epoch_timeout_us),
            faults: FaultCounter::new(FaultSource::Gps, config.fault_interval_us),
            last_sync_us: None,
            stats: GpsStats {
                lines: 0,
                ignored: 0,
                proprietary_rejected: 0,
                fixes: 0,
                faults: [0; FAULT_CODES],
            },
        }
    }

    /// The configuration in force.
    #[must_use]
    pub const fn config(&self) -> &GpsConfig {
        &self.config
    }

    /// Feeds a chunk of bytes whose last byte arrived at `t_last_us`.
    pub fn feed(&mut self, bytes: &[u8], t_last_us: u64, out: &mut impl FnMut(GpsEvent)) {
        let n = bytes.len() as u64;
        for (i, &b) in bytes.iter().enumerate() {
            let back = self.char_time_ns().saturating_mul(n - 1 - i as u64) / 1000;
            self.push_byte(b, t_last_us.saturating_sub(back), out);
        }
    }

    /// Feeds one byte that arrived at `t_us`.
    pub fn push_byte(&mut self, byte: u8, t_us: u64, out: &mut impl FnMut(GpsEvent)) {
        let Self {
            line,
            epoch,
            faults,
            stats,
            ..
        } = self;
        let mut fault = |code, t| faults.count(code, t, &mut |f| out(GpsEvent::Fault(f)));
        let mut fixes = heapless::Vec::<GpsFix, 2>::new();
        match line.push(byte, t_us) {
            None => {}
            Some(LineEvent::Rejected {
                proprietary: true, ..
            }) => stats.proprietary_rejected = stats.proprietary_rejected.saturating_add(1),
            Some(LineEvent::Rejected { error, t_us, .. }) => fault(fault_code(error), t_us),
            Some(LineEvent::Valid { text, t_us }) => {
                stats.lines = stats.lines.saturating_add(1);
                match sentence::parse(text) {
                    Sentence::Ignored => stats.ignored = stats.ignored.saturating_add(1),
                    Sentence::Unparseable(_) => fault(FAULT_UNPARSEABLE, t_us),
                    Sentence::OutOfRange(_) => fault(FAULT_OUT_OF_RANGE, t_us),
                    Sentence::Update(kind, update) => {
                        if update.hdop_out_of_range {
                            fault(FAULT_OUT_OF_RANGE, t_us);
                        }
                        // One sentence ends at most two epochs: the previous
                        // one and, when it is the learned closer, its own.
                        epoch.push(kind, &update, t_us, &mut |f| {
                            let _ = fixes.push(f);
                        });
                    }
                }
            }
        }
        for fix in fixes {
            self.emit_fix(fix, out);
        }
    }

    /// Emits what is due at `now_us` without new bytes: an epoch whose
    /// sentences stopped coming, and fault counts waiting for their interval.
    /// Call it periodically (every 100 ms is plenty).
    pub fn poll(&mut self, now_us: u64, out: &mut impl FnMut(GpsEvent)) {
        let mut fix = None;
        self.epoch.poll(now_us, &mut |f| fix = Some(f));
        if let Some(f) = fix {
            self.emit_fix(f, out);
        }
        self.faults.poll(now_us, &mut |f| out(GpsEvent::Fault(f)));
    }

    /// End of input: emits the open epoch and every pending fault count.
    pub fn finish(&mut self, now_us: u64, out: &mut impl FnMut(GpsEvent)) {
        let mut fix = None;
        self.epoch.flush(&mut |f| fix = Some(f));
        if let Some(f) = fix {
            self.emit_fix(f, out);
        }
        self.faults.flush(now_us, &mut |f| out(GpsEvent::Fault(f)));
    }

    /// Counters since boot.
    #[must_use]
    pub fn stats(&self) -> GpsStats {
        let mut stats = self.stats;
        for (code, n) in (1u8..).zip(stats.faults.iter_mut()) {
            *n = self.faults.total(code);
        }
        stats
    }

    /// How long `chars` characters take on the wire at the configured
    /// baud, µs (0 when back-dating is off).
    #[must_use]
    pub fn chars_us(&self, chars: usize) -> u64 {
        self.char_time_ns().saturating_mul(chars as u64) / 1000
    }

    fn char_time_ns(&self) -> u64 {
        // 8N1: start bit, 8 data bits, stop bit.
        10_000_000_000u64
            .checked_div(u64::from(self.config.baud))
            .unwrap_or(0)
    }

    fn emit_fix(&mut self, mut fix: GpsFix, out: &mut impl FnMut(GpsEvent)) {
        if fix.utc.is_some_and(|u| !u.is_valid()) {
            // A leap second on a day that cannot end with one: a receiver
            // error, counted; the fix goes without its UTC, as the decoder
            // would drop it (`format::limits`).
            fix.utc = None;
            self.faults.count(FAULT_OUT_OF_RANGE, fix.t_us, &mut |f| {
                out(GpsEvent::Fault(f))
            });
        }
        self.stats.fixes = self.stats.fixes.saturating_add(1);
        out(GpsEvent::Fix(fix));
        let Some(utc) = fix.utc.filter(|_| fix.fix != FixMode::None) else {
            return;
        };
        let due = self
            .last_sync_us
            .is_none_or(|last| fix.t_us.saturating_sub(last) >= self.config.utc_sync_interval_us);
        if due {
            // The pair is (start of the epoch's first sentence, UTC of the
            // fix): it carries the receiver's output latency as a constant
            // offset, typically tens of milliseconds.
            self.last_sync_us = Some(fix.t_us);
            out(GpsEvent::UtcSync(UtcSync {
                t_us: fix.t_us,
                unix_ms: utc.unix_ms(),
            }));
        }
    }
}

fn fault_code(error: LineError) -> u8 {
    match error {
        LineError::Checksum => FAULT_CHECKSUM,
        LineError::NoChecksum => FAULT_NO_CHECKSUM,
        LineError::Overlong => FAULT_OVERLONG,
        LineError::Framing => FAULT_FRAMING,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const EPOCHS: &str = "\
$GPRMC,113258,A,3238.9148,N,10822.4466,W,005.3,247.1,181022,009.3,E*6B\r\n\
$GPGGA,113258,3238.9148,N,10822.4466,W,2,08,1.1,1577.4,M,-24.6,M,,*4D\r\n\
$GPGSA,A,3,02,05,11,12,18,20,25,29,,,,,1.4,1.1,0.9*3D\r\n\
$PGRME,7.6,M,41.7,M,42.4,M*2F\r\n\
$GPRMC,113259,A,3238.9145,N,10822.4482,W,005.0,246.3,181022,009.3,E*6D\r\n\
$GPGGA,113259,3238.9145,N,10822.4482,W,2,08,1.1,1577.9,M,-24.6,M,,*46\r\n\
$GPGSA,A,3,02,05,11,12,18,20,25,29,,,,,1.4,1.1,0.9*3D\r\n";

    fn run(rx: &mut GpsReceiver, bytes: &[u8]) -> Vec<GpsEvent> {
        let mut out = Vec::new();
        for (i, &b) in bytes.iter().enumerate() {
            rx.push_byte(b, i as u64 * 100, &mut |e| out.push(e));
        }
        rx.finish(bytes.len() as u64 * 100, &mut |e| out.push(e));
        out
    }

    #[test]
    fn fixes_and_a_utc_sync() {
        let mut rx = GpsReceiver::new(GpsConfig::default());
        let out = run(&mut rx, EPOCHS.as_bytes());
        let fixes: Vec<_> = out
            .iter()
            .filter_map(|e| match e {
                GpsEvent::Fix(f) => Some(*f),
                _ => None,
            })
            .collect();
        assert_eq!(fixes.len(), 2);
        let second_start = EPOCHS.find("$GPRMC,113259").unwrap() as u64 * 100;
        assert_eq!(fixes[1].t_us, second_start);
        let syncs: Vec<_> = out
            .iter()
            .filter_map(|e| match e {
                GpsEvent::UtcSync(s) => Some(*s),
                _ => None,
            })
            .collect();
        // 2022-10-18T11:32:58Z
        assert_eq!(
            syncs,
            [UtcSync {
                t_us: 0,
                unix_ms: 1_666_092_778_000
            }]
        );
        let stats = rx.stats();
        assert_eq!((stats.lines, stats.ignored, stats.fixes), (7, 1, 2));
        assert_eq!(stats.faults, [0; FAULT_CODES]);
    }

    #[test]
    fn chunked_feed_back_dates_each_byte() {
        let mut rx = GpsReceiver::new(GpsConfig {
            baud: 10_000, // 1 ms per character
            ..GpsConfig::default()
        });
        let mut out = Vec::new();
        let bytes = EPOCHS.as_bytes();
        // One chunk whose last byte arrives at t = 10 s.
        rx.feed(bytes, 10_000_000, &mut |e| out.push(e));
        rx.finish(10_000_000, &mut |e| out.push(e));
        let GpsEvent::Fix(first) = out[0] else {
            panic!("{out:?}")
        };
        assert_eq!(first.t_us, 10_000_000 - (bytes.len() as u64 - 1) * 1000);
    }

    #[test]
    fn faults_are_counted_by_code() {
        let mut rx = GpsReceiver::new(GpsConfig::default());
        let input = "\
$GPRMC,113258,A,3238.9148,N,10822.4466,W,005.3,247.1,181022,009.3,E*6C\r\n\
$STI,IC,error=4\r\n\
$GPGGA,1132\
$GPRMC,1,X*22\r\n\
$POLYN,TIME,RESTART_OCCURRED\r\n";
        let out = run(&mut rx, input.as_bytes());
        let codes: Vec<_> = out
            .iter()
            .filter_map(|e| match e {
                GpsEvent::Fault(f) => Some((f.code, f.count)),
                _ => None,
            })
            .collect();
        assert_eq!(
            codes,
            [
                (FAULT_CHECKSUM, 1),
                (FAULT_NO_CHECKSUM, 1),
                (FAULT_FRAMING, 1),
                (FAULT_UNPARSEABLE, 1)
            ]
        );
        let stats = rx.stats();
        assert_eq!(stats.faults, [1, 1, 0, 1, 1, 0]);
        assert_eq!(stats.proprietary_rejected, 1);
        assert_eq!(stats.fixes, 0);
    }
}
