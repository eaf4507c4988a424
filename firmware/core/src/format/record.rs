//! The records a card log holds, as plain values.
//!
//! Fields are the quantised integers stored on the card; names carry units and
//! scales (`steer_cdeg` is hundredths of a degree). Conversions to physical
//! units live next to each type so the encoder, the decoder and the sensor
//! code agree on one definition. The byte layout is in `firmware/FORMAT.md`.

/// Accelerometer scale: counts per g (±16 g full scale in an `i16`).
pub const ACCEL_COUNTS_PER_G: f32 = 2048.0;
/// Gyroscope scale: counts per degree per second (±1024 deg/s in an `i16`).
pub const GYRO_COUNTS_PER_DPS: f32 = 32.0;
/// Steering scale: counts per degree (hundredths of a degree).
pub const STEER_COUNTS_PER_DEG: f32 = 100.0;
/// `Frame::wheel_edge_age_us` value meaning "no edge in the last 65.534 ms".
pub const EDGE_AGE_NONE: u16 = u16::MAX;

/// A physical value that can be quantised: `f32` in the firmware (hardware
/// floating point, no soft-float `f64` on the sampling path) and `f64` on the
/// host (CSV input, where the error must stay within half a count).
pub trait Physical: Copy {
    /// `self × counts_per_unit`, rounded half away from zero, saturated to
    /// the `i32` range (NaN gives 0).
    fn counts(self, counts_per_unit: f32) -> i32;
}

impl Physical for f32 {
    fn counts(self, counts_per_unit: f32) -> i32 {
        // Adding the half and letting `as` truncate toward zero rounds half
        // away from zero without `f32::round`, which needs std.
        let x = self * counts_per_unit;
        (if x >= 0.0 { x + 0.5 } else { x - 0.5 }) as i32
    }
}

impl Physical for f64 {
    fn counts(self, counts_per_unit: f32) -> i32 {
        let x = self * f64::from(counts_per_unit);
        (if x >= 0.0 { x + 0.5 } else { x - 0.5 }) as i32
    }
}

/// Round and saturate a physical value into an `i16` field.
#[must_use]
pub fn quantise_i16(value: impl Physical, counts_per_unit: f32) -> i16 {
    value
        .counts(counts_per_unit)
        .clamp(i16::MIN.into(), i16::MAX.into()) as i16
}

/// Round and saturate a physical value into a `u16` field.
#[must_use]
pub fn quantise_u16(value: impl Physical, counts_per_unit: f32) -> u16 {
    value.counts(counts_per_unit).clamp(0, u16::MAX.into()) as u16
}

/// Round and saturate a physical value into an `i32` field (positions, on
/// the host and in the GPS path: computed in `f64`).
#[must_use]
pub fn quantise_i32(value: f64, counts_per_unit: f64) -> i32 {
    let x = value * counts_per_unit;
    (if x >= 0.0 { x + 0.5 } else { x - 0.5 }) as i32
}

#[cfg(test)]
mod quantise_tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn within_half_a_count_and_saturating(v in -100.0f64..100.0, k in prop::sample::select(vec![2048.0f32, 32.0, 100.0, 1000.0])) {
            let exact = v * f64::from(k);
            let q = f64::from(quantise_i16(v, k));
            let clamped = exact.clamp(f64::from(i16::MIN), f64::from(i16::MAX));
            prop_assert!((q - clamped).abs() <= 0.5 + 1e-9, "{} {}", q, exact);
            // The f32 path agrees with the f64 one up to f32's own rounding.
            let q32 = f64::from(quantise_i16(v as f32, k));
            prop_assert!((q32 - q).abs() <= 1.0);
            let u = f64::from(quantise_u16(v, k));
            prop_assert!((u - exact.clamp(0.0, 65535.0)).abs() <= 0.5 + 1e-9);
        }
    }

    #[test]
    fn nan_is_zero() {
        assert_eq!(quantise_i16(f32::NAN, 100.0), 0);
        assert_eq!(quantise_u16(f64::NAN, 100.0), 0);
    }
}

/// Status bits of a 100 Hz frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameStatus(pub u8);

impl FrameStatus {
    /// The IMU produced no new sample since the previous frame.
    pub const IMU_STALE: u8 = 1 << 0;
    /// The steering ADC produced no new value since the previous frame.
    pub const STEER_STALE: u8 = 1 << 1;
    /// The steering value hit the ADC's range (pot at an end stop or unplugged).
    pub const STEER_SATURATED: u8 = 1 << 2;
    /// No wheel edge within the stall timeout: speed is reported as zero.
    pub const WHEEL_STOPPED: u8 = 1 << 3;
    /// No GPS fix within the last second.
    pub const GPS_STALE: u8 = 1 << 4;
    /// The IMU is missing or stuck (values not changing).
    pub const IMU_FAULT: u8 = 1 << 5;
    /// The wobble alert is active in this frame.
    pub const ALERT: u8 = 1 << 6;
    /// The rider's marker button is held in this frame.
    pub const MARKER: u8 = 1 << 7;

    /// Whether every bit of `mask` is set.
    #[must_use]
    pub const fn has(self, mask: u8) -> bool {
        self.0 & mask == mask
    }
}

/// One 100 Hz sample of every channel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Frame {
    /// Microseconds since boot.
    pub t_us: u64,
    /// Acceleration x/y/z in the bicycle frame, [`ACCEL_COUNTS_PER_G`].
    pub accel: [i16; 3],
    /// Angular rate x/y/z in the bicycle frame, [`GYRO_COUNTS_PER_DPS`].
    pub gyro: [i16; 3],
    /// Steering angle, hundredths of a degree, positive to the left.
    pub steer_cdeg: i16,
    /// Cumulative wheel pulse count since boot, wrapping at 2^16.
    pub wheel_count: u16,
    /// Age of the last wheel edge at `t_us`, microseconds ([`EDGE_AGE_NONE`] if older).
    pub wheel_edge_age_us: u16,
    /// Wheel speed, millimetres per second.
    pub speed_mm_s: u16,
    /// Status bits.
    pub status: FrameStatus,
}

impl Frame {
    /// Acceleration in g.
    #[must_use]
    pub fn accel_g(&self) -> [f32; 3] {
        self.accel.map(|c| f32::from(c) / ACCEL_COUNTS_PER_G)
    }
    /// Angular rate in degrees per second.
    #[must_use]
    pub fn gyro_dps(&self) -> [f32; 3] {
        self.gyro.map(|c| f32::from(c) / GYRO_COUNTS_PER_DPS)
    }
    /// Steering angle in degrees.
    #[must_use]
    pub fn steer_deg(&self) -> f32 {
        f32::from(self.steer_cdeg) / STEER_COUNTS_PER_DEG
    }
    /// Wheel speed in metres per second.
    #[must_use]
    pub fn speed_mps(&self) -> f32 {
        f32::from(self.speed_mm_s) / 1000.0
    }
}

/// GPS fix dimension.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FixMode {
    /// No fix (position fields, if present, are not trustworthy).
    #[default]
    None,
    /// Two-dimensional fix.
    Fix2d,
    /// Three-dimensional fix.
    Fix3d,
}

impl FixMode {
    /// The name used in CSV and JSON output.
    #[must_use]
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::Fix2d => "2d",
            Self::Fix3d => "3d",
        }
    }
}

/// UTC date and time of day, millisecond resolution.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct UtcTime {
    /// Days since 2000-01-01.
    pub days_since_2000: u16,
    /// Milliseconds since midnight UTC (a leap second may reach 86 400 999).
    pub ms_of_day: u32,
}

impl UtcTime {
    /// Milliseconds since the Unix epoch.
    #[must_use]
    pub fn unix_ms(self) -> u64 {
        const DAYS_1970_TO_2000: u64 = 10_957;
        (DAYS_1970_TO_2000 + u64::from(self.days_since_2000)) * 86_400_000
            + u64::from(self.ms_of_day)
    }

    /// Civil date (year, month 1-12, day 1-31) of `days_since_2000`.
    #[must_use]
    pub fn date(self) -> (i32, u32, u32) {
        // Howard Hinnant's days-to-civil algorithm, shifted to the 2000 epoch.
        let z = i64::from(self.days_since_2000) + 10_957 + 719_468;
        let era = z.div_euclid(146_097);
        let doe = z - era * 146_097;
        let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
        let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
        let mp = (5 * doy + 2) / 153;
        let day = (doy - (153 * mp + 2) / 5 + 1) as u32;
        let month = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
        let year = (yoe + era * 400 + i64::from(month <= 2)) as i32;
        (year, month, day)
    }

    /// Days since 2000-01-01 of a civil date, `None` outside 2000..=2179
    /// or for a day the month does not have (2026-02-30).
    #[must_use]
    pub fn days_from_date(year: i32, month: u32, day: u32) -> Option<u16> {
        if !(1..=12).contains(&month) || day == 0 || day > days_in_month(year, month) {
            return None;
        }
        let y = i64::from(year) - i64::from(month <= 2);
        let era = y.div_euclid(400);
        let yoe = y - era * 400;
        let m = i64::from(month);
        let doy = (153 * (if m > 2 { m - 3 } else { m + 9 }) + 2) / 5 + i64::from(day) - 1;
        let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
        let days = era * 146_097 + doe - 719_468 - 10_957;
        u16::try_from(days).ok()
    }
}

/// Days in `month` (1-12) of `year` in the Gregorian calendar.
#[must_use]
pub const fn days_in_month(year: i32, month: u32) -> u32 {
    let leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
    match month {
        2 if leap => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    }
}

/// One GPS epoch, merged from the sentences the receiver sent for it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GpsFix {
    /// Local time (µs since boot) at which the epoch's first sentence began.
    pub t_us: u64,
    /// UTC of the fix, if the receiver sent one.
    pub utc: Option<UtcTime>,
    /// Latitude, 1e-7 degrees, north positive.
    pub lat_e7: Option<i32>,
    /// Longitude, 1e-7 degrees, east positive.
    pub lon_e7: Option<i32>,
    /// Speed over ground, centimetres per second.
    pub speed_cm_s: Option<u16>,
    /// Course over ground, hundredths of a degree from true north.
    pub course_cdeg: Option<u16>,
    /// Altitude above mean sea level, centimetres.
    pub alt_cm: Option<i32>,
    /// Fix dimension.
    pub fix: FixMode,
    /// Satellites used in the fix.
    pub sats: Option<u8>,
    /// Horizontal dilution of precision, tenths (saturates at 25.5).
    pub hdop_d: Option<u8>,
}

/// A (local time, UTC) pair, written when the GPS time first becomes valid and
/// then periodically, so every sample can be given an absolute time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct UtcSync {
    /// Local time, µs since boot.
    pub t_us: u64,
    /// UTC at that instant, milliseconds since the Unix epoch.
    pub unix_ms: u64,
}

/// The wobble alert switching on or off.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Alert {
    /// Local time, µs since boot.
    pub t_us: u64,
    /// `true` when the alert switches on.
    pub on: bool,
    /// Dominant frequency, hundredths of a hertz (0 when switching off).
    pub freq_chz: u16,
    /// Steering oscillation amplitude, hundredths of a degree (0 when off).
    pub amp_cdeg: u16,
}

/// The rider pressed the marker button.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Marker {
    /// Local time, µs since boot.
    pub t_us: u64,
    /// Running marker number since boot.
    pub id: u16,
}

/// Why frames were dropped before reaching the card.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DropoutReason {
    /// The queue to the SD writer was full (card stalled longer than designed).
    QueueFull,
    /// No card, or the card failed: frames were sampled but could not be written.
    CardUnavailable,
    /// The sampler missed its tick (overrun).
    SamplerOverrun,
    /// A reason this reader does not know (from a newer writer).
    Other(u8),
}

impl DropoutReason {
    /// The byte stored on the card.
    #[must_use]
    pub const fn code(self) -> u8 {
        match self {
            Self::QueueFull => 1,
            Self::CardUnavailable => 2,
            Self::SamplerOverrun => 3,
            Self::Other(c) => c,
        }
    }
    /// Inverse of [`Self::code`].
    #[must_use]
    pub const fn from_code(code: u8) -> Self {
        match code {
            1 => Self::QueueFull,
            2 => Self::CardUnavailable,
            3 => Self::SamplerOverrun,
            c => Self::Other(c),
        }
    }
    /// Short name for reports.
    #[must_use]
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::QueueFull => "queue_full",
            Self::CardUnavailable => "card_unavailable",
            Self::SamplerOverrun => "sampler_overrun",
            Self::Other(_) => "other",
        }
    }
}

/// Frames that were sampled but never reached the card.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Dropout {
    /// Local time of the first lost frame, µs since boot.
    pub t_us: u64,
    /// How many 100 Hz frames were lost.
    pub frames_lost: u32,
    /// Why.
    pub reason: DropoutReason,
}

/// The component a fault came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FaultSource {
    /// The IMU.
    Imu,
    /// The steering potentiometer / ADC.
    Steering,
    /// The wheel-speed sensor.
    Wheel,
    /// The GPS receiver or its NMEA stream.
    Gps,
    /// The SD card or file system.
    Card,
    /// The configuration file.
    Config,
    /// The logger itself (watchdog reset, overrun).
    System,
    /// A source this reader does not know (from a newer writer).
    Other(u8),
}

impl FaultSource {
    /// The byte stored on the card.
    #[must_use]
    pub const fn code(self) -> u8 {
        match self {
            Self::Imu => 1,
            Self::Steering => 2,
            Self::Wheel => 3,
            Self::Gps => 4,
            Self::Card => 5,
            Self::Config => 6,
            Self::System => 7,
            Self::Other(c) => c,
        }
    }
    /// Inverse of [`Self::code`].
    #[must_use]
    pub const fn from_code(code: u8) -> Self {
        match code {
            1 => Self::Imu,
            2 => Self::Steering,
            3 => Self::Wheel,
            4 => Self::Gps,
            5 => Self::Card,
            6 => Self::Config,
            7 => Self::System,
            c => Self::Other(c),
        }
    }
    /// Short name for reports.
    #[must_use]
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::Imu => "imu",
            Self::Steering => "steering",
            Self::Wheel => "wheel",
            Self::Gps => "gps",
            Self::Card => "card",
            Self::Config => "config",
            Self::System => "system",
            Self::Other(_) => "other",
        }
    }
}

/// A sensor or card fault, counted. Codes per source are listed in `FORMAT.md`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Fault {
    /// Local time, µs since boot.
    pub t_us: u64,
    /// Where it happened.
    pub source: FaultSource,
    /// What happened, per source.
    pub code: u8,
    /// How many times since the previous fault record of the same kind.
    pub count: u16,
}

/// A kick's ring-down as the on-board detector measured it
/// (`wobble_core::detector::Kick`): the stable wobble mode's frequency and
/// growth rate at the speed of the kick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct KickRingDown {
    /// Local time of the kick, µs since boot (the record is written when the
    /// ring has been measured, up to about 2 s later).
    pub t_us: u64,
    /// Mean wheel speed over the ring, mm/s (`None`: unknown).
    pub speed_mm_s: Option<u16>,
    /// Ring frequency, hundredths of a hertz.
    pub freq_chz: u16,
    /// Growth rate, thousandths of 1/s (negative: the ring decays).
    pub sigma_milli_per_s: i16,
    /// Standard error of the growth rate, thousandths of 1/s.
    pub sigma_se_milli_per_s: u16,
    /// Ring amplitude at the kick, hundredths of a degree.
    pub amp_cdeg: u16,
    /// Demodulation segments the fit used.
    pub segments: u8,
}

impl KickRingDown {
    /// Speed, m/s.
    #[must_use]
    pub fn speed_mps(&self) -> Option<f32> {
        self.speed_mm_s.map(|v| f32::from(v) / 1000.0)
    }
    /// Frequency, Hz.
    #[must_use]
    pub fn freq_hz(&self) -> f32 {
        f32::from(self.freq_chz) / 100.0
    }
    /// Growth rate, 1/s.
    #[must_use]
    pub fn sigma_per_s(&self) -> f32 {
        f32::from(self.sigma_milli_per_s) / 1000.0
    }
    /// Standard error of the growth rate, 1/s.
    #[must_use]
    pub fn sigma_se_per_s(&self) -> f32 {
        f32::from(self.sigma_se_milli_per_s) / 1000.0
    }
    /// Amplitude at the kick, degrees.
    #[must_use]
    pub fn amp_deg(&self) -> f32 {
        f32::from(self.amp_cdeg) / 100.0
    }
}

/// What a margin record says (format 1.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum MarginState {
    /// A kick updated the running estimate of the wobble speed.
    Estimate,
    /// The speed came within `alert.margin_mps` of the estimate's lower
    /// bound: the "approaching" pattern started.
    Approaching,
    /// The speed has stayed clear of it: the pattern stopped.
    Clear,
    /// A state of a later minor version.
    Other(u8),
}

impl MarginState {
    /// The code on the card.
    #[must_use]
    pub fn code(self) -> u8 {
        match self {
            Self::Estimate => 0,
            Self::Approaching => 1,
            Self::Clear => 2,
            Self::Other(c) => c,
        }
    }

    /// The state of a code on the card.
    #[must_use]
    pub fn from_code(code: u8) -> Self {
        match code {
            0 => Self::Estimate,
            1 => Self::Approaching,
            2 => Self::Clear,
            c => Self::Other(c),
        }
    }
}

/// The on-board margin warning's state and estimate
/// (`wobble_core::detector::MarginWarning`): the wobble speed the ride's
/// kicks predict, with its 95 % interval, and the speed at the time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MarginRecord {
    /// Local time, µs since boot.
    pub t_us: u64,
    /// What happened.
    pub state: MarginState,
    /// Wheel speed at the time, mm/s (`None`: unknown).
    pub speed_mm_s: Option<u16>,
    /// Lower end of the wobble speed's 95 % interval, mm/s (`None`: no
    /// estimate).
    pub lower_mm_s: Option<u16>,
    /// The predicted wobble speed, mm/s (`None`: only a lower bound).
    pub estimate_mm_s: Option<u16>,
    /// Upper end of the interval, mm/s (`None`: open).
    pub upper_mm_s: Option<u16>,
    /// Kicks the estimate was made from.
    pub kicks: u8,
}

/// A speed in mm/s below the "unknown" code 0xFFFF.
fn speed_mm_s(v: f32) -> u16 {
    quantise_u16(v, 1000.0).min(u16::MAX - 1)
}

impl MarginRecord {
    /// The record of `state` at `now_us`, with the speed then and the
    /// estimate in force (if any).
    #[must_use]
    pub fn new(
        now_us: u64,
        state: MarginState,
        speed_mps: Option<f32>,
        estimate: Option<&crate::detector::WobbleSpeed>,
    ) -> Self {
        Self {
            t_us: now_us,
            state,
            speed_mm_s: speed_mps.map(speed_mm_s),
            lower_mm_s: estimate.map(|e| speed_mm_s(e.lower_mps)),
            estimate_mm_s: estimate.and_then(|e| e.estimate_mps).map(speed_mm_s),
            upper_mm_s: estimate.and_then(|e| e.upper_mps).map(speed_mm_s),
            kicks: estimate.map_or(0, |e| e.kicks),
        }
    }
}

/// Identity of the logger and firmware that wrote a log (file header).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LogInfo<'a> {
    /// Local time, µs since boot, when the log was opened.
    pub t_us: u64,
    /// Firmware version string.
    pub firmware: &'a str,
    /// Unique device id (the MCU's 96-bit UID on the board).
    pub device_id: [u8; 12],
    /// Nominal frame rate.
    pub sample_rate_hz: u16,
    /// Run number on this card (`RUN00001.WBL` is 1).
    pub run: u32,
}

/// One channel of the frame, for self-description.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ChannelDef<'a> {
    /// Local time, µs since boot (the header's time).
    pub t_us: u64,
    /// Position of the field in the frame record.
    pub index: u8,
    /// Channel name, as in the CSV header without the unit.
    pub name: &'a str,
    /// Physical unit.
    pub unit: &'a str,
    /// Physical value = stored integer / `counts_per_unit`.
    pub counts_per_unit: f32,
}

/// One `key=value` line of the configuration in force.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ConfigLine<'a> {
    /// Local time, µs since boot (the header's time).
    pub t_us: u64,
    /// The line, without newline.
    pub text: &'a str,
}

/// Anything a card log holds.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Record<'a> {
    /// 100 Hz sample frame.
    Frame(Frame),
    /// GPS fix.
    Gps(GpsFix),
    /// Local time / UTC pair.
    UtcSync(UtcSync),
    /// Wobble alert on or off.
    Alert(Alert),
    /// Rider marker.
    Marker(Marker),
    /// Frames lost before reaching the card.
    Dropout(Dropout),
    /// Counted sensor or card fault.
    Fault(Fault),
    /// Header: logger and firmware identity.
    LogInfo(LogInfo<'a>),
    /// Header: channel definition.
    Channel(ChannelDef<'a>),
    /// Header: configuration line.
    Config(ConfigLine<'a>),
    /// A kick's measured ring-down (format 1.1).
    Kick(KickRingDown),
    /// The margin warning's estimate or switching (format 1.2).
    Margin(MarginRecord),
}

impl Record<'_> {
    /// Local time of the record, µs since boot.
    #[must_use]
    pub fn t_us(&self) -> u64 {
        match self {
            Self::Frame(r) => r.t_us,
            Self::Gps(r) => r.t_us,
            Self::UtcSync(r) => r.t_us,
            Self::Alert(r) => r.t_us,
            Self::Marker(r) => r.t_us,
            Self::Dropout(r) => r.t_us,
            Self::Fault(r) => r.t_us,
            Self::LogInfo(r) => r.t_us,
            Self::Channel(r) => r.t_us,
            Self::Config(r) => r.t_us,
            Self::Kick(r) => r.t_us,
            Self::Margin(r) => r.t_us,
        }
    }
}
