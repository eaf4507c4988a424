//! The field self-test: what the board measured about each part, whether
//! that is good enough to ride, and the `SELFTEST.TXT` report.
//!
//! The board runs the test when the marker button is held at power-on (or
//! `selftest=1` is in `CONFIG.TXT`): the rider holds the bike still, then
//! turns the handlebar and spins the front wheel by hand during
//! [`TEST_WINDOW_US`]. The board only gathers [`Measurements`]; the
//! verdicts and the report are here, so they are tested on the host and
//! `wobblog selftest` reads the same format back.
//!
//! Report format, one check per line after a header line:
//!
//! ```text
//! wobble self-test 1
//! imu PASS who_am_i=0x47 accel_g=1.01
//! steering FAIL counts=2011..2013 (turn the handlebar)
//! ```

use core::fmt::{self, Write};

use embedded_sdmmc::{Block, BlockDevice, BlockIdx};

use crate::boot::{BorCheck, ResetCause};
use crate::drivers::icm42688::reg::WHO_AM_I_VALUE;
use crate::imu_clock::NOMINAL_PERIOD_US;
use crate::logger::layout::{u16_at, u32_at, FatLayout};
use crate::supply::SupplyCheck;

/// How long the rider turns the bar and spins the wheel, µs.
pub const TEST_WINDOW_US: u64 = 10_000_000;
/// First line of every report (the number is the format's version).
pub const HEADER: &str = "wobble self-test 1";

/// At rest the accelerometer reads 1 g; more than 10 % off is a wrong
/// scale, a broken axis or a bike being moved.
const ONE_G_TOLERANCE: f32 = 0.10;
/// ADC counts (12 bits): the wiper must stay off both rails (a rail means
/// an open end or a short) and move by at least this much when the bar is
/// turned (about 15 degrees with the default calibration).
const ADC_RAIL_MARGIN: u16 = 40;
const ADC_FULL_SCALE: u16 = 4095;
const MIN_STEER_SWING_COUNTS: u16 = 200;
/// Edges while the wheel is spun by hand: one revolution of the disc.
const MIN_WHEEL_EDGES: u32 = 50;
/// The log needs about 3 KiB/s; a card must write far faster to absorb
/// its own stalls, and read fast enough for the logger's FAT work.
const MIN_CARD_KIB_S: u32 = 100;
/// An hour of logging is about 11 MB.
const MIN_FREE_MIB: u32 = 64;
/// The IMU's data-ready pulses must come at its configured output data
/// rate ([`NOMINAL_PERIOD_US`]) to within this, in per mille: the sensor's
/// own oscillator is within a few per cent (the sample clock absorbs that
/// while riding), a wrong rate is off by a factor.
const DATA_READY_TOLERANCE_PER_MILLE: u64 = 30;
/// Pulses at least, over the [`DATA_READY_WINDOW_US`] window (a full second
/// brings 100).
const MIN_DATA_READY_PULSES: u32 = 50;
/// How long the board counts data-ready pulses, µs.
pub const DATA_READY_WINDOW_US: u64 = 1_000_000;

/// The IMU's data-ready line (INT1) over the self-test's window: the pulses
/// counted, their first and last time and the longest gap between two, µs
/// on the MCU clock.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PulseTrain {
    /// Pulses seen.
    pub pulses: u32,
    /// Time of the first pulse.
    pub first_us: u64,
    /// Time of the last pulse.
    pub last_us: u64,
    /// Longest time between two consecutive pulses.
    pub longest_gap_us: u64,
}

impl PulseTrain {
    /// Adds the next pulse, at `t_us` (pulses come in order).
    pub fn pulse(&mut self, t_us: u64) {
        if self.pulses == 0 {
            self.first_us = t_us;
        } else {
            let gap = t_us.saturating_sub(self.last_us);
            self.longest_gap_us = self.longest_gap_us.max(gap);
        }
        self.last_us = t_us;
        self.pulses = self.pulses.saturating_add(1);
    }

    /// The mean time between pulses, µs; `None` with fewer than two.
    #[must_use]
    pub fn mean_period_us(&self) -> Option<u64> {
        let intervals = u64::from(self.pulses.checked_sub(1)?);
        (intervals > 0).then(|| (self.last_us - self.first_us) / intervals)
    }

    /// Whether the line pulses at the configured rate: enough pulses, a
    /// mean period within the tolerance, and no pulse missing (no gap of
    /// one and a half periods).
    #[must_use]
    pub fn at_rate(&self) -> bool {
        let nominal = u64::from(NOMINAL_PERIOD_US);
        self.pulses >= MIN_DATA_READY_PULSES
            && self.mean_period_us().is_some_and(|t| {
                t.abs_diff(nominal) * 1000 <= nominal * DATA_READY_TOLERANCE_PER_MILLE
            })
            && self.longest_gap_us * 2 <= nominal * 3
    }
}

/// What the board measured.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Measurements {
    /// The IMU's `WHO_AM_I`, if it answered.
    pub imu_id: Option<u8>,
    /// Mean acceleration magnitude at rest, g, if it delivered samples.
    pub accel_g: Option<f32>,
    /// Lowest and highest steering ADC count during the window.
    pub steer_counts: Option<(u16, u16)>,
    /// Wheel edges during the window.
    pub wheel_edges: u32,
    /// The baud rate the GPS receiver was found at, if it was.
    pub gps_baud: Option<u32>,
    /// Its fix rate after set-up, Hz.
    pub gps_rate_hz: u32,
    /// Card write and read speed, KiB/s, if the card worked.
    pub card_kib_s: Option<(u32, u32)>,
    /// Free space on the card, MiB.
    pub card_free_mib: u32,
    /// The card answered but holds no FAT16 or FAT32 volume the logger can
    /// write (exFAT, GPT, unformatted).
    pub card_unusable: bool,
    /// Whether the crystal runs (else the HSI).
    pub crystal: bool,
    /// Why the MCU last reset.
    pub reset: Option<ResetCause>,
    /// The brown-out level, and what the self-test did about it.
    pub bor: Option<BorCheck>,
    /// Deepest stack use since power-on, and the stack's size, bytes.
    pub stack_bytes: Option<(u32, u32)>,
    /// The IMU's data-ready pulses over [`DATA_READY_WINDOW_US`], if
    /// counted.
    pub imu_data_ready: Option<PulseTrain>,
}

/// At most this share of the stack, in percent, may have been used: the
/// ride's interrupts (sampler, GPS) nest on top of what the self-test saw.
const MAX_STACK_USE_PERCENT: u32 = 50;

/// One check's result.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Verdict {
    /// Good to ride.
    Pass,
    /// Fix before riding.
    Fail,
}

/// The checks, in report order (the LED code of a failure is its index
/// plus one).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Check {
    /// IMU identity and 1 g at rest.
    Imu,
    /// Steering ADC in range and moving.
    Steering,
    /// Wheel edges while spun.
    Wheel,
    /// GPS sentences found at some baud.
    Gps,
    /// Card speed and free space.
    Card,
    /// Crystal running.
    Clock,
    /// The last reset was a normal one.
    Reset,
    /// The brown-out reset at 2.7 V is stored in the option bytes.
    Bor,
    /// The stack's high-water mark leaves room.
    Stack,
    /// The IMU's data-ready line pulses at its output data rate.
    ImuDataReady,
}

/// Every check, in order.
pub const CHECKS: [Check; 10] = [
    Check::Imu,
    Check::Steering,
    Check::Wheel,
    Check::Gps,
    Check::Card,
    Check::Clock,
    Check::Reset,
    Check::Bor,
    Check::Stack,
    Check::ImuDataReady,
];

impl Check {
    /// Its name in the report.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Imu => "imu",
            Self::Steering => "steering",
            Self::Wheel => "wheel",
            Self::Gps => "gps",
            Self::Card => "card",
            Self::Clock => "clock",
            Self::Reset => "reset",
            Self::Bor => "bor",
            Self::Stack => "stack",
            Self::ImuDataReady => "imu_drdy",
        }
    }

    /// The verdict on `m`.
    #[must_use]
    pub fn verdict(self, m: &Measurements) -> Verdict {
        let pass = match self {
            Self::Imu => {
                m.imu_id == Some(WHO_AM_I_VALUE)
                    && m.accel_g
                        .is_some_and(|g| (g - 1.0).abs() <= ONE_G_TOLERANCE)
            }
            Self::Steering => m.steer_counts.is_some_and(|(lo, hi)| {
                lo >= ADC_RAIL_MARGIN
                    && hi <= ADC_FULL_SCALE - ADC_RAIL_MARGIN
                    && hi.saturating_sub(lo) >= MIN_STEER_SWING_COUNTS
            }),
            Self::Wheel => m.wheel_edges >= MIN_WHEEL_EDGES,
            Self::Gps => m.gps_baud.is_some() && m.gps_rate_hz >= 1,
            Self::Card => {
                m.card_kib_s
                    .is_some_and(|(w, r)| w >= MIN_CARD_KIB_S && r >= MIN_CARD_KIB_S)
                    && m.card_free_mib >= MIN_FREE_MIB
            }
            Self::Clock => m.crystal,
            Self::Reset => m.reset.is_some_and(|r| !r.is_abnormal()),
            // Programmed is not yet verified: only the next power cycle
            // loads the stored bytes.
            Self::Bor => m.bor == Some(BorCheck::Level3),
            Self::Stack => m
                .stack_bytes
                .is_some_and(|(used, size)| used * 100 <= size * MAX_STACK_USE_PERCENT),
            Self::ImuDataReady => m.imu_data_ready.is_some_and(|p| p.at_rate()),
        };
        if pass {
            Verdict::Pass
        } else {
            Verdict::Fail
        }
    }

    /// What was measured, for the report.
    fn detail(self, m: &Measurements, out: &mut impl Write) -> fmt::Result {
        match self {
            Self::Imu => match (m.imu_id, m.accel_g) {
                (None, _) => out.write_str("no answer"),
                (Some(id), None) => write!(out, "who_am_i=0x{id:02x} no samples"),
                (Some(id), Some(g)) => {
                    // Hundredths by integer arithmetic: no float formatting
                    // code in the firmware for one figure (a magnitude, >= 0).
                    let cg = (g * 100.0 + 0.5) as u32;
                    write!(
                        out,
                        "who_am_i=0x{id:02x} accel_g={}.{:02}",
                        cg / 100,
                        cg % 100
                    )
                }
            },
            Self::Steering => match m.steer_counts {
                None => out.write_str("no conversions"),
                Some((lo, hi)) => write!(out, "counts={lo}..{hi} (turn the handlebar)"),
            },
            Self::Wheel => write!(out, "edges={} (spin the wheel)", m.wheel_edges),
            Self::Gps => match m.gps_baud {
                None => out.write_str("no NMEA at any baud"),
                Some(b) => write!(out, "found_baud={b} rate_hz={}", m.gps_rate_hz),
            },
            Self::Card => match m.card_kib_s {
                None if m.card_unusable => out.write_str(
                    "no FAT16 or FAT32 volume (exFAT, GPT or unformatted): format it FAT32",
                ),
                None => out.write_str("not readable"),
                Some((w, r)) => write!(
                    out,
                    "write_kib_s={w} read_kib_s={r} free_mib={}",
                    m.card_free_mib
                ),
            },
            Self::Clock => out.write_str(if m.crystal { "crystal" } else { "internal RC" }),
            Self::Reset => match m.reset {
                None => out.write_str("unknown"),
                Some(r) => write!(out, "cause={r:?}"),
            },
            Self::Bor => match m.bor {
                None => out.write_str("not checked"),
                Some(BorCheck::Level3) => out.write_str("level=3 (2.7 V)"),
                Some(BorCheck::Programmed { was }) => write!(
                    out,
                    "was={was:?} programmed level 3 (power-cycle, then run the self-test again)"
                ),
                Some(BorCheck::Failed { was, flash_sr }) => {
                    write!(out, "was={was:?} not programmed flash_sr=0x{flash_sr:02x}")
                }
                Some(BorCheck::SupplyTooLow { was, vdd_mv: None }) => write!(
                    out,
                    "was={was:?} not programmed: supply not measured (VREFINT)"
                ),
                Some(BorCheck::SupplyTooLow {
                    was,
                    vdd_mv: Some(mv),
                }) => write!(
                    out,
                    "was={was:?} not programmed: supply measured {mv} mV is too low to enable \
                     level 3 (needs {} mV)",
                    crate::supply::MIN_VDD_FOR_BOR3_MV
                ),
            },
            Self::Stack => match m.stack_bytes {
                None => out.write_str("not measured"),
                Some((used, size)) => write!(out, "used={used} of {size} bytes"),
            },
            Self::ImuDataReady => match m.imu_data_ready {
                None => out.write_str("not measured"),
                Some(p) if p.pulses == 0 => out.write_str("no pulses (INT1 to PA1)"),
                Some(p) => write!(
                    out,
                    "pulses={} period_us={} longest_gap_us={}",
                    p.pulses,
                    p.mean_period_us().unwrap_or(0),
                    p.longest_gap_us
                ),
            },
        }
    }
}

/// The first failing check's LED code (its position, from 1), or 0 when
/// every check passed.
#[must_use]
pub fn failure_code(m: &Measurements) -> u8 {
    CHECKS
        .iter()
        .position(|c| c.verdict(m) == Verdict::Fail)
        .map_or(0, |i| i as u8 + 1)
}

/// Writes the report (see the module docs).
///
/// # Errors
/// `out`'s error (a full buffer).
pub fn write_report(m: &Measurements, out: &mut impl Write) -> fmt::Result {
    writeln!(out, "{HEADER}")?;
    for check in CHECKS {
        let verdict = match check.verdict(m) {
            Verdict::Pass => "PASS",
            Verdict::Fail => "FAIL",
        };
        write!(out, "{} {verdict} ", check.name())?;
        check.detail(m, out)?;
        writeln!(out)?;
    }
    Ok(())
}

/// The record queue's line of the report, written after the checks of
/// [`CHECKS`] (`queue PASS capacity=576 holds_ms=4608 high_water=3 ...`):
/// the queue this boot and what the card measured means for it. A check of
/// its own, apart from [`Measurements`], so that reports and readers of the
/// ten checks before it stay as they are; a failure shows as LED code
/// [`QUEUE_LED_CODE`] ([`overall_code`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct QueueCheck {
    /// The queue's capacity, records.
    pub capacity: u32,
    /// Its high-water mark this boot, records.
    pub high_water: u32,
    /// The card's slowest block write during the speed test (one
    /// embedded-sdmmc write call, FAT updates included), µs; `None`
    /// without a working card.
    pub slowest_write_us: Option<u32>,
}

/// LED code of a failed queue check: after the ten of [`CHECKS`].
pub const QUEUE_LED_CODE: u8 = CHECKS.len() as u8 + 1;

impl QueueCheck {
    /// The longest writer iteration this card would take, µs: every one of
    /// the iteration's most operations
    /// ([`crate::channels::WRITER_OPS_PER_ITERATION`]) as slow as its
    /// slowest write (an over-estimate: reads are faster).
    #[must_use]
    pub fn predicted_iteration_us(&self) -> Option<u64> {
        self.slowest_write_us
            .map(|us| u64::from(us) * u64::from(crate::channels::WRITER_OPS_PER_ITERATION))
    }

    /// The queue's fill after that iteration at the highest record rate.
    #[must_use]
    pub fn predicted_high_water(&self) -> Option<u64> {
        self.predicted_iteration_us()
            .map(|us| crate::channels::records_for(us, crate::channels::MAX_RECORDS_PER_S))
    }

    /// Pass when this card's predicted worst iteration fits the queue.
    #[must_use]
    pub fn verdict(&self) -> Verdict {
        match self.predicted_high_water() {
            Some(records) if records <= u64::from(self.capacity) => Verdict::Pass,
            _ => Verdict::Fail,
        }
    }

    /// Writes the report line (with its newline).
    ///
    /// # Errors
    /// `out`'s error (a full buffer).
    pub fn write_line(&self, out: &mut impl Write) -> fmt::Result {
        let verdict = match self.verdict() {
            Verdict::Pass => "PASS",
            Verdict::Fail => "FAIL",
        };
        let holds_ms = crate::channels::queue_holds_us(
            u64::from(self.capacity),
            crate::channels::MAX_RECORDS_PER_S,
        ) / 1000;
        write!(
            out,
            "queue {verdict} capacity={} holds_ms={holds_ms} high_water={}",
            self.capacity, self.high_water
        )?;
        match (
            self.slowest_write_us,
            self.predicted_iteration_us(),
            self.predicted_high_water(),
        ) {
            (Some(write_us), Some(iteration_us), Some(records)) => writeln!(
                out,
                " slowest_write_us={write_us} worst_iteration_ms={} predicted_high_water={records}",
                iteration_us / 1000
            ),
            _ => writeln!(out, " card not measured"),
        }
    }
}

/// The LED code of the whole self-test: the first failing check of
/// [`CHECKS`] ([`failure_code`]), else [`QUEUE_LED_CODE`] if the queue's
/// check failed, else [`crate::supply::SUPPLY_LED_CODE`] if the supply's
/// did, else 0.
#[must_use]
pub fn overall_code(m: &Measurements, queue: &QueueCheck, supply: &SupplyCheck) -> u8 {
    match failure_code(m) {
        0 if queue.verdict() == Verdict::Fail => QUEUE_LED_CODE,
        0 if supply.verdict() == Verdict::Fail => crate::supply::SUPPLY_LED_CODE,
        code => code,
    }
}

/// One line of a report read back.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ReportLine<'a> {
    /// The check's name.
    pub check: &'a str,
    /// Its verdict.
    pub verdict: Verdict,
    /// What was measured.
    pub detail: &'a str,
}

/// Why a report could not be read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReportError {
    /// The first line is not [`HEADER`].
    NotAReport,
    /// This line (from 1) is not `name PASS|FAIL detail`.
    BadLine(usize),
}

impl fmt::Display for ReportError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotAReport => write!(f, "not a self-test report (no \"{HEADER}\" line)"),
            Self::BadLine(n) => write!(f, "line {n} is not `check PASS|FAIL detail`"),
        }
    }
}

/// Reads a report back, calling `line` for each check line.
///
/// # Errors
/// [`ReportError`] for anything but a report as [`write_report`] makes.
pub fn read_report<'a>(
    text: &'a str,
    line: &mut impl FnMut(ReportLine<'a>),
) -> Result<(), ReportError> {
    let mut lines = text.lines();
    if lines.next().map(str::trim_end) != Some(HEADER) {
        return Err(ReportError::NotAReport);
    }
    for (i, l) in lines.enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let mut parts = l.splitn(3, ' ');
        let (Some(check), Some(verdict)) = (parts.next(), parts.next()) else {
            return Err(ReportError::BadLine(i + 2));
        };
        let verdict = match verdict {
            "PASS" => Verdict::Pass,
            "FAIL" => Verdict::Fail,
            _ => return Err(ReportError::BadLine(i + 2)),
        };
        line(ReportLine {
            check,
            verdict,
            detail: parts.next().unwrap_or("").trim_end(),
        });
    }
    Ok(())
}

/// Free space of the card's first partition, MiB, counted in its first
/// FAT: the clusters whose entry is 0, FAT16 or FAT32 (embedded-sdmmc has
/// no free-space query of its own). Not FAT32's FSInfo count: the FAT
/// specification calls it a hint that may be stale, and a driver that
/// filled the card may leave it anything. `None` for anything but a FAT16
/// or FAT32 volume on 512-byte sectors, or a FAT that cannot be read. One
/// block read per 128 (FAT32) or 256 (FAT16) clusters: some 8000 reads on
/// a 32 GB card of 32 KiB clusters.
pub fn fat_free_mib<D: BlockDevice>(card: &D) -> Option<u32> {
    let layout = FatLayout::of(card)?;
    let mut block = [Block::new()];
    let mut read = |idx: u32| -> Option<[u8; 512]> {
        card.read(&mut block, BlockIdx(idx)).ok()?;
        Some(block[0].contents)
    };
    let FatLayout {
        fat_start: fat,
        entry_bytes,
        clusters,
        per_cluster,
        ..
    } = layout;
    let mut free = 0u32;
    let mut sector = None;
    let mut data = [0u8; 512];
    for cluster in 2..clusters + 2 {
        let at = cluster * entry_bytes;
        if sector != Some(at / 512) {
            sector = Some(at / 512);
            data = read(fat.checked_add(at / 512)?)?;
        }
        let i = (at % 512) as usize;
        let entry = if entry_bytes == 2 {
            u16_at(&data, i)
        } else {
            u32_at(&data, i) & 0x0FFF_FFFF
        };
        free += u32::from(entry == 0);
    }
    let free_bytes = u64::from(free) * u64::from(per_cluster) * 512;
    u32::try_from(free_bytes >> 20).ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boot::BorLevel;

    fn good() -> Measurements {
        Measurements {
            imu_id: Some(0x47),
            accel_g: Some(1.01),
            steer_counts: Some((1700, 2300)),
            wheel_edges: 180,
            gps_baud: Some(9_600),
            gps_rate_hz: 20,
            card_kib_s: Some((900, 1800)),
            card_free_mib: 30_000,
            card_unusable: false,
            crystal: true,
            reset: Some(ResetCause::PowerOn),
            bor: Some(BorCheck::Level3),
            stack_bytes: Some((14_000, 86_000)),
            imu_data_ready: Some(pulses(100, 10_150, 0)),
        }
    }

    /// The report `write_report` makes of `m`.
    fn report_of(m: &Measurements) -> String {
        let mut text = String::new();
        write_report(m, &mut text).unwrap();
        text
    }

    /// `n` pulses `period_us` apart from 5 s on, the one after pulse
    /// `missing` (if not 0) left out.
    fn pulses(n: u32, period_us: u64, missing: u32) -> PulseTrain {
        let mut p = PulseTrain::default();
        for k in 0..n {
            if missing == 0 || k != missing {
                p.pulse(5_000_000 + u64::from(k) * period_us);
            }
        }
        p
    }

    /// The queue's line: a card whose slowest write, at every operation of
    /// the writer's worst iteration, still fits the queue passes; one that
    /// does not, or no card, fails with code 11 after every other check.
    #[test]
    fn the_queue_line_judges_the_card_against_the_queue() {
        let fast = QueueCheck {
            capacity: 576,
            high_water: 3,
            slowest_write_us: Some(40_000),
        };
        // 14 operations at 40 ms: 560 ms, 70 records at 125 a second.
        assert_eq!(fast.predicted_iteration_us(), Some(560_000));
        assert_eq!(fast.predicted_high_water(), Some(70));
        assert_eq!(fast.verdict(), Verdict::Pass);
        let mut line = String::new();
        fast.write_line(&mut line).unwrap();
        assert_eq!(
            line,
            "queue PASS capacity=576 holds_ms=4608 high_water=3 slowest_write_us=40000 \
             worst_iteration_ms=560 predicted_high_water=70\n"
        );
        // 330 ms per write: 4.62 s, 578 records: over.
        let slow = QueueCheck {
            slowest_write_us: Some(330_000),
            ..fast
        };
        assert_eq!(slow.predicted_high_water(), Some(578));
        assert_eq!(slow.verdict(), Verdict::Fail);
        // 329 ms: 4.606 s, 576 records: just fits.
        let edge = QueueCheck {
            slowest_write_us: Some(329_000),
            ..fast
        };
        assert_eq!(edge.verdict(), Verdict::Pass);
        let none = QueueCheck {
            slowest_write_us: None,
            ..fast
        };
        assert_eq!(none.verdict(), Verdict::Fail);
        let mut line = String::new();
        none.write_line(&mut line).unwrap();
        assert_eq!(
            line,
            "queue FAIL capacity=576 holds_ms=4608 high_water=3 card not measured\n"
        );
        // The report with the queue's line reads back, eleven checks.
        let mut text = report_of(&good());
        slow.write_line(&mut text).unwrap();
        let mut names = Vec::new();
        read_report(&text, &mut |l| names.push((l.check, l.verdict))).unwrap();
        assert_eq!(names.len(), 11);
        assert_eq!(names[10], ("queue", Verdict::Fail));
        // LED codes: the other checks first, then the queue's, then the
        // supply's.
        let supply = SupplyCheck {
            reading: crate::supply::measure(&[1500; 16], 1500),
        };
        let low = SupplyCheck {
            reading: crate::supply::measure(&[1678; 16], 1500),
        };
        assert_eq!(overall_code(&good(), &fast, &supply), 0);
        assert_eq!(overall_code(&good(), &slow, &supply), 11);
        assert_eq!(overall_code(&good(), &slow, &low), 11);
        assert_eq!(overall_code(&good(), &fast, &low), 12);
        assert_eq!(overall_code(&good(), &fast, &SupplyCheck::default()), 12);
        let mut bad = good();
        bad.wheel_edges = 0;
        assert_eq!(overall_code(&bad, &slow, &low), 3);
    }

    #[test]
    fn a_good_board_passes_everything() {
        let m = good();
        assert!(CHECKS.iter().all(|c| c.verdict(&m) == Verdict::Pass));
        assert_eq!(failure_code(&m), 0);
    }

    #[test]
    fn each_fault_fails_its_own_check_and_gives_its_code() {
        type Spoil = fn(&mut Measurements);
        let cases: [(Check, Spoil); 24] = [
            (Check::Imu, |m| m.imu_id = Some(0x00)),
            (Check::Imu, |m| m.accel_g = Some(0.5)),
            (Check::Imu, |m| m.accel_g = None),
            (Check::Steering, |m| m.steer_counts = Some((2000, 2010))),
            (Check::Steering, |m| m.steer_counts = Some((0, 900))),
            (Check::Steering, |m| m.steer_counts = Some((3000, 4095))),
            (Check::Wheel, |m| m.wheel_edges = 49),
            (Check::Gps, |m| m.gps_baud = None),
            (Check::Card, |m| m.card_kib_s = Some((50, 1800))),
            (Check::Card, |m| m.card_free_mib = 10),
            (Check::Clock, |m| m.crystal = false),
            (Check::Reset, |m| m.reset = Some(ResetCause::Watchdog)),
            (Check::Bor, |m| m.bor = None),
            (Check::Bor, |m| {
                m.bor = Some(BorCheck::Programmed { was: BorLevel::Off });
            }),
            (Check::Bor, |m| {
                m.bor = Some(BorCheck::Failed {
                    was: BorLevel::Off,
                    flash_sr: 1 << 4,
                });
            }),
            // A supply too low for level 3: kept, and the check fails.
            (Check::Bor, |m| {
                m.bor = Some(BorCheck::SupplyTooLow {
                    was: BorLevel::Off,
                    vdd_mv: Some(2950),
                });
            }),
            (Check::Stack, |m| m.stack_bytes = Some((43_001, 86_000))),
            (Check::Stack, |m| m.stack_bytes = None),
            // INT1 not wired, or the sensor not pulsing.
            (Check::ImuDataReady, |m| {
                m.imu_data_ready = Some(pulses(0, 0, 0))
            }),
            (Check::ImuDataReady, |m| m.imu_data_ready = None),
            // A sensor at 50 Hz or 200 Hz instead of its 100 Hz.
            (Check::ImuDataReady, |m| {
                m.imu_data_ready = Some(pulses(50, 20_000, 0));
            }),
            (Check::ImuDataReady, |m| {
                m.imu_data_ready = Some(pulses(200, 5_000, 0));
            }),
            // 4 % fast: outside the 3 % the oscillator may be off.
            (Check::ImuDataReady, |m| {
                m.imu_data_ready = Some(pulses(104, 9_600, 0));
            }),
            // One pulse missing in the second.
            (Check::ImuDataReady, |m| {
                m.imu_data_ready = Some(pulses(100, 10_000, 40));
            }),
        ];
        for (check, spoil) in cases {
            let mut m = good();
            spoil(&mut m);
            let failed: Vec<Check> = CHECKS
                .into_iter()
                .filter(|c| c.verdict(&m) == Verdict::Fail)
                .collect();
            assert_eq!(failed, [check], "{m:?}");
            let code = CHECKS.iter().position(|&c| c == check).unwrap() as u8 + 1;
            assert_eq!(failure_code(&m), code);
        }
    }

    /// The `bor` line says why level 3 was not programmed.
    #[test]
    fn a_supply_too_low_for_level_3_is_named_in_the_bor_line() {
        let line = |vdd_mv| {
            let m = Measurements {
                bor: Some(BorCheck::SupplyTooLow {
                    was: BorLevel::Off,
                    vdd_mv,
                }),
                ..good()
            };
            let text = report_of(&m);
            text.lines()
                .find(|l| l.starts_with("bor "))
                .unwrap()
                .to_owned()
        };
        assert_eq!(
            line(Some(2950)),
            "bor FAIL was=Off not programmed: supply measured 2950 mV is too low to enable \
             level 3 (needs 3070 mV)"
        );
        assert_eq!(
            line(None),
            "bor FAIL was=Off not programmed: supply not measured (VREFINT)"
        );
    }

    #[test]
    fn a_silent_data_ready_line_is_named_in_the_report() {
        let m = Measurements {
            imu_data_ready: Some(PulseTrain::default()),
            ..good()
        };
        let text = report_of(&m);
        assert!(
            text.ends_with("imu_drdy FAIL no pulses (INT1 to PA1)\n"),
            "{text}"
        );
        assert_eq!(failure_code(&m), 10);
        let m = good();
        let text = report_of(&m);
        assert!(
            text.ends_with("imu_drdy PASS pulses=100 period_us=10150 longest_gap_us=10150\n"),
            "{text}"
        );
    }

    /// An exFAT card fails the card check with what to do about it, not
    /// as a card that cannot be read; the failure code is the card's (5).
    #[test]
    fn an_unusable_card_is_named_in_the_report() {
        let unusable = Measurements {
            card_kib_s: None,
            card_free_mib: 0,
            card_unusable: true,
            ..good()
        };
        let text = report_of(&unusable);
        assert!(
            text.contains("\ncard FAIL no FAT16 or FAT32 volume (exFAT, GPT or unformatted): format it FAT32\n"),
            "{text}"
        );
        assert_eq!(failure_code(&unusable), 5);
        let silent = Measurements {
            card_unusable: false,
            ..unusable
        };
        let text = report_of(&silent);
        assert!(text.contains("\ncard FAIL not readable\n"), "{text}");
    }

    #[test]
    fn a_pulse_train_measures_its_period_and_gaps() {
        let p = pulses(100, 10_000, 40);
        assert_eq!(p.pulses, 99);
        assert_eq!(p.longest_gap_us, 20_000);
        // 99 pulses over 99 periods: 98 intervals of 990 000 / 98 µs.
        assert_eq!(p.mean_period_us(), Some(10_102));
        assert!(!p.at_rate());
        assert!(pulses(100, 10_290, 0).at_rate());
        assert!(!pulses(100, 10_310, 0).at_rate());
        assert!(pulses(100, 9_710, 0).at_rate());
        assert!(!pulses(49, 10_000, 0).at_rate());
        assert_eq!(pulses(1, 10_000, 0).mean_period_us(), None);
    }

    #[test]
    fn the_report_reads_back_line_for_line() {
        let mut m = good();
        m.wheel_edges = 3;
        let text = report_of(&m);
        assert!(text.starts_with("wobble self-test 1\nimu PASS who_am_i=0x47 accel_g=1.01\n"));
        let mut lines = Vec::new();
        read_report(&text, &mut |l| lines.push(l)).unwrap();
        assert_eq!(lines.len(), CHECKS.len());
        assert_eq!(
            lines[2],
            ReportLine {
                check: "wheel",
                verdict: Verdict::Fail,
                detail: "edges=3 (spin the wheel)"
            }
        );
        assert_eq!(
            read_report("hello\n", &mut |_| {}),
            Err(ReportError::NotAReport)
        );
        assert_eq!(
            read_report("wobble self-test 1\nimu MAYBE x\n", &mut |_| {}),
            Err(ReportError::BadLine(2))
        );
    }

    /// A line without a verdict is named by its number in the file (blank
    /// lines counted), and the message says which.
    #[test]
    fn a_line_without_a_verdict_is_named_by_its_number() {
        let text = "wobble self-test 1\nimu PASS x\n\nwheel PASS y\nsteering\n";
        let err = read_report(text, &mut |_| {}).unwrap_err();
        assert_eq!(err, ReportError::BadLine(5));
        assert_eq!(err.to_string(), "line 5 is not `check PASS|FAIL detail`");
        assert!(ReportError::NotAReport.to_string().contains(HEADER));
    }

    /// The measured magnitude goes into the report to the hundredth,
    /// rounded, also far from 1 g.
    #[test]
    fn the_report_shows_the_measured_acceleration() {
        for (g, shown) in [
            (0.87, "accel_g=0.87"),
            (1.234, "accel_g=1.23"),
            (2.006, "accel_g=2.01"),
        ] {
            let m = Measurements {
                accel_g: Some(g),
                ..good()
            };
            let text = report_of(&m);
            let imu = text.lines().nth(1).unwrap();
            assert!(imu.starts_with("imu FAIL") && imu.ends_with(shown), "{imu}");
        }
    }
}
