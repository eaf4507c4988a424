//! `CONFIG.TXT`: the rider-editable configuration on the card.
//!
//! The file holds `key=value` lines; `#` starts a comment (whole line or
//! after a value), blank lines are ignored, keys are case-sensitive, and
//! whitespace around keys and values is ignored. A missing file or key means
//! the default, which is each module's own `Default` ([`WheelConfig`],
//! [`SteeringCalibration`], [`ImuConfig`], [`DetectorConfig`],
//! [`PatternConfig`]), so the firmware and the host tools agree on what a
//! blank card does.
//!
//! Nothing in the file can stop the logger: a line that cannot be understood
//! is skipped and reported as a [`LineFault`] (written to the log as a
//! [`FaultSource::Config`] fault), and a section whose values do not make
//! sense together (say `detector.amp_off_deg` above `detector.amp_on_deg`)
//! falls back to its defaults as a whole, also reported. Whatever is in force
//! afterwards is written into the log header by [`Config::write_lines`], in
//! the same `key=value` syntax, so a log says exactly how it was recorded and the
//! lines can be pasted back into a `CONFIG.TXT`.

use core::fmt;

use embedded_sdmmc::{BlockDevice, Mode, TimeSource, VolumeIdx, VolumeManager};

use crate::detector::{
    ApproachConfig, ConfigError as DetectorConfigError, Detector, DetectorConfig, PatternConfig,
};
use crate::format::{Fault, FaultSource};
use crate::imu::{AxisMap, Imu, ImuConfig, SignedAxis};
use crate::steering::{CalPoint, Steering, SteeringCalibration};
use crate::wheel::{WheelConfig, WheelSpeed};

/// Fault code: a line without `=` or with an empty key.
pub const FAULT_SYNTAX: u8 = 1;
/// Fault code: a key this firmware does not know (a typo, or a newer file).
pub const FAULT_UNKNOWN_KEY: u8 = 2;
/// Fault code: a value that does not parse as the key's type (or is NaN,
/// infinite, negative for a count, too large for its field).
pub const FAULT_BAD_VALUE: u8 = 3;
/// Fault code: values that parse but do not work together; their section
/// (wheel, steering, IMU, detector) fell back to its defaults.
pub const FAULT_REJECTED: u8 = 4;
/// Fault code: a line that is not UTF-8, or the part of a file too long to
/// be read.
pub const FAULT_UNREADABLE: u8 = 5;
/// Fault code: a key of an older firmware whose value now comes from another
/// key; the line is skipped. `detector.wheel_circumference_m`: the detector
/// places the wheel's harmonics with `wheel.circumference_m`, the wheel the
/// speed is measured with.
pub const FAULT_OBSOLETE_KEY: u8 = 6;
/// Number of config fault codes (`1..=FAULT_CODES`).
pub const FAULT_CODES: usize = 6;

/// The file's name in the card's root directory.
pub const FILE_NAME: &str = "CONFIG.TXT";

/// Line faults kept with their line numbers (the counts stay exact beyond).
pub const MAX_LINE_FAULTS: usize = 8;

/// Longest text [`Config::write_lines`] produces, for any configuration
/// (checked by a test with every value at its widest).
pub const MAX_TEXT_LEN: usize = 2048;

/// Whether the rider is told about a wobble and about approaching the
/// wobble speed, and how.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AlertConfig {
    /// Drive the buzzer and alert LED. When off, alerts and margin
    /// warnings are still detected and logged, the rider just is not told
    /// (blind trials). Default on.
    pub enabled: bool,
    /// Beep timing of the wobble alert.
    pub pattern: PatternConfig,
    /// The margin warning sounds when the speed comes within this much of
    /// the lower bound of the wobble speed the ride's kicks predict, m/s
    /// ([`crate::detector::MarginWarning`]). 0 to 5.
    pub margin_mps: f32,
    /// Beep timing of the margin warning.
    pub approach: ApproachConfig,
}

/// Default of [`AlertConfig::margin_mps`], m/s: about one speed step of
/// the kick-test protocol (`host-tools/docs/kick-testing.md`).
pub const DEFAULT_MARGIN_MPS: f32 = 0.5;
/// Largest [`AlertConfig::margin_mps`], m/s.
pub const MAX_MARGIN_MPS: f32 = 5.0;

impl AlertConfig {
    /// Whether the values work together: a margin of 0 to
    /// [`MAX_MARGIN_MPS`], and a beep group that fits its period.
    #[must_use]
    pub fn is_valid(&self) -> bool {
        (0.0..=MAX_MARGIN_MPS).contains(&self.margin_mps) && self.approach.is_valid()
    }
}

impl Default for AlertConfig {
    fn default() -> Self {
        Self {
            enabled: true,
            pattern: PatternConfig::DEFAULT,
            margin_mps: DEFAULT_MARGIN_MPS,
            approach: ApproachConfig::DEFAULT,
        }
    }
}

/// Everything `CONFIG.TXT` can set.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// Wheel-speed sensor.
    pub wheel: WheelConfig,
    /// Steering potentiometer calibration.
    pub steering: SteeringCalibration,
    /// IMU mounting and health check. The sensitivities are the driver's
    /// business: the file cannot set them.
    pub imu: ImuConfig,
    /// Wobble detector.
    pub detector: DetectorConfig,
    /// Rider alert.
    pub alert: AlertConfig,
}

/// The sections that are validated (and fall back to defaults) as a whole,
/// in the order of [`SECTIONS`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Section {
    Wheel,
    Steering,
    Imu,
    Detector,
    Alert,
}

/// How a section is checked and put back to its defaults.
struct SectionRules {
    valid: fn(&Config) -> bool,
    reset: fn(&mut Config),
}

/// Indexed by [`Section`]. Each check is the one the module applies when it
/// is built, so the firmware never starts a module on values it refuses.
const SECTIONS: [SectionRules; 5] = [
    SectionRules {
        valid: |c| WheelSpeed::try_new(c.wheel).is_ok(),
        reset: |c| c.wheel = WheelConfig::default(),
    },
    SectionRules {
        valid: |c| Steering::try_new(c.steering).is_ok(),
        reset: |c| c.steering = SteeringCalibration::default(),
    },
    SectionRules {
        valid: |c| Imu::try_new(c.imu).is_ok(),
        reset: |c| c.imu = ImuConfig::default(),
    },
    SectionRules {
        valid: |c| c.detector.cost().is_ok(),
        reset: |c| c.detector = DetectorConfig::default(),
    },
    SectionRules {
        valid: |c| c.alert.is_valid(),
        reset: |c| c.alert = AlertConfig::default(),
    },
];

/// A value type a key can hold: how it is read from and written to text.
trait Field: Copy {
    fn parse(text: &str) -> Option<Self>;
    fn write(self, out: &mut dyn TextOut) -> fmt::Result;
}

impl Field for f32 {
    fn parse(text: &str) -> Option<Self> {
        text.parse::<f32>().ok().filter(|v| v.is_finite())
    }
    fn write(self, out: &mut dyn TextOut) -> fmt::Result {
        let mut text = [0u8; FLOAT_TEXT_LEN];
        let len = shortest_text(self, &mut text);
        out.write_str(core::str::from_utf8(text.get(..len).unwrap_or_default()).unwrap_or("0"))
    }
}

/// Longest text [`shortest_text`] writes: sign, 9 digits, point, `e-45`.
const FLOAT_TEXT_LEN: usize = 16;

/// Writes the shortest decimal text (1 to 9 significant digits) that reads
/// back as exactly `v`, so the header lines round-trip; plain below 10^7
/// and from 10^-4, with an exponent outside. Returns the length.
///
/// The core's float formatting would do this too, but it links about
/// 10 KiB of tables and code into the firmware for a few dozen lines
/// written once per boot: this searches digit counts with the parser the
/// firmware has anyway.
fn shortest_text(v: f32, out: &mut [u8; FLOAT_TEXT_LEN]) -> usize {
    if v == 0.0 || !v.is_finite() {
        out[0] = b'0';
        return 1;
    }
    let magnitude = f64::from(v.abs());
    // Decimal exponent: 10^exp <= magnitude < 10^(exp + 1).
    let mut exp: i32 = 0;
    while pow10(exp + 1) <= magnitude {
        exp += 1;
    }
    while pow10(exp) > magnitude {
        exp -= 1;
    }
    for digits in 1..=9 {
        // `magnitude` scaled to `digits` integer digits, rounded; an f64
        // holds it with 15 digits to spare.
        let mut mantissa = (magnitude * pow10(digits - 1 - exp) + 0.5) as u64;
        let mut e = exp;
        if mantissa >= 10u64.pow(digits as u32) {
            mantissa /= 10;
            e += 1;
        }
        let len = layout(v < 0.0, mantissa, digits as usize, e, out);
        let text = core::str::from_utf8(out.get(..len).unwrap_or_default()).unwrap_or("");
        if text.parse::<f32>() == Ok(v) {
            return len;
        }
    }
    // Unreachable: 9 significant digits identify every f32.
    out[0] = b'0';
    1
}

/// 10^`exp` (the exponents used stay within -55..=48).
fn pow10(exp: i32) -> f64 {
    let mut p = 1.0f64;
    for _ in 0..exp.unsigned_abs() {
        p *= 10.0;
    }
    if exp < 0 {
        1.0 / p
    } else {
        p
    }
}

/// Writes `mantissa` (`digits` digits) × 10^(`exp` − `digits` + 1) into
/// `out`; returns the length.
fn layout(negative: bool, mantissa: u64, digits: usize, exp: i32, out: &mut [u8]) -> usize {
    let mut ascii = [b'0'; 9];
    let mut m = mantissa;
    for slot in ascii.iter_mut().take(digits).rev() {
        *slot = b'0' + (m % 10) as u8;
        m /= 10;
    }
    // Trailing zeros carry nothing.
    let mut used = digits;
    while used > 1 && ascii[used - 1] == b'0' {
        used -= 1;
    }
    let significant = ascii.get(..used).unwrap_or_default();
    let mut w = Writer { out, len: 0 };
    if negative {
        w.push(b'-');
    }
    if (-4..7).contains(&exp) {
        let point = exp + 1; // digits before the decimal point
        if point <= 0 {
            w.push(b'0');
            w.push(b'.');
            (0..-point).for_each(|_| w.push(b'0'));
            significant.iter().for_each(|&d| w.push(d));
        } else {
            let point = point as usize;
            (0..point).for_each(|i| w.push(significant.get(i).copied().unwrap_or(b'0')));
            if used > point {
                w.push(b'.');
                significant
                    .get(point..)
                    .unwrap_or_default()
                    .iter()
                    .for_each(|&d| w.push(d));
            }
        }
    } else {
        w.push(significant[0]);
        if used > 1 {
            w.push(b'.');
            significant
                .get(1..)
                .unwrap_or_default()
                .iter()
                .for_each(|&d| w.push(d));
        }
        w.push(b'e');
        if exp < 0 {
            w.push(b'-');
        }
        let e = exp.unsigned_abs();
        if e >= 10 {
            w.push(b'0' + (e / 10) as u8);
        }
        w.push(b'0' + (e % 10) as u8);
    }
    w.len
}

/// Where config text goes: `fmt::Write` without `write_fmt`. A `dyn
/// fmt::Write` vtable links all of `core::fmt` into the firmware; this one
/// holds only the two methods the writers use.
pub trait TextOut {
    /// Appends a string.
    ///
    /// # Errors
    /// When the output is full.
    fn write_str(&mut self, s: &str) -> fmt::Result;
    /// Appends a character.
    ///
    /// # Errors
    /// When the output is full.
    fn write_char(&mut self, c: char) -> fmt::Result;
}

impl<W: fmt::Write> TextOut for W {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        fmt::Write::write_str(self, s)
    }
    fn write_char(&mut self, c: char) -> fmt::Result {
        fmt::Write::write_char(self, c)
    }
}

/// Appends bytes to a slice, dropping what does not fit.
struct Writer<'a> {
    out: &'a mut [u8],
    len: usize,
}

impl Writer<'_> {
    fn push(&mut self, byte: u8) {
        if let Some(slot) = self.out.get_mut(self.len) {
            *slot = byte;
            self.len += 1;
        }
    }
}

macro_rules! unsigned_field {
    ($($t:ty),+) => {$(
        impl Field for $t {
            fn parse(text: &str) -> Option<Self> {
                text.parse().ok()
            }
            fn write(self, out: &mut dyn TextOut) -> fmt::Result {
                write_unsigned(out, u32::from(self))
            }
        }
    )+};
}
unsigned_field!(u8, u16, u32);

/// Decimal digits of `value`. Written out rather than with `write!`, which
/// would link `core::fmt`'s integer formatting into the firmware.
fn write_unsigned(out: &mut dyn TextOut, mut value: u32) -> fmt::Result {
    let mut ascii = [0u8; 10];
    let mut start = ascii.len();
    loop {
        start -= 1;
        ascii[start] = b'0' + (value % 10) as u8;
        value /= 10;
        if value == 0 {
            break;
        }
    }
    ascii[start..]
        .iter()
        .try_for_each(|&d| out.write_char(char::from(d)))
}

/// Mounting axes as text: `+x`, `-y`, ...
const AXIS_NAMES: [(&str, SignedAxis); 6] = [
    ("+x", SignedAxis::PosX),
    ("-x", SignedAxis::NegX),
    ("+y", SignedAxis::PosY),
    ("-y", SignedAxis::NegY),
    ("+z", SignedAxis::PosZ),
    ("-z", SignedAxis::NegZ),
];

/// `+x,+y,+z`: for the bicycle's x (forward), y (left) and z (up), the
/// sensor axis along it.
impl Field for AxisMap {
    fn parse(text: &str) -> Option<Self> {
        let mut parts = text.split(',').map(|part| {
            let part = part.trim();
            AXIS_NAMES
                .iter()
                .find(|(name, _)| *name == part)
                .map(|&(_, axis)| axis)
        });
        let map = [parts.next()??, parts.next()??, parts.next()??];
        parts.next().is_none().then_some(Self(map))
    }
    fn write(self, out: &mut dyn TextOut) -> fmt::Result {
        for (i, axis) in self.0.iter().enumerate() {
            let name = AXIS_NAMES
                .iter()
                .find(|(_, a)| a == axis)
                .map_or("?", |(n, _)| n);
            out.write_str(if i == 0 { "" } else { "," })?;
            out.write_str(name)?;
        }
        Ok(())
    }
}

/// `none`, or three `counts:deg` points separated by commas.
impl Field for Option<[CalPoint; 3]> {
    fn parse(text: &str) -> Option<Self> {
        if text == "none" {
            return Some(None);
        }
        let mut points = text.split(',').map(|point| {
            let (counts, deg) = point.split_once(':')?;
            Some(CalPoint {
                counts: f32::parse(counts.trim())?,
                deg: f32::parse(deg.trim())?,
            })
        });
        let three = [points.next()??, points.next()??, points.next()??];
        points.next().is_none().then_some(Some(three))
    }
    fn write(self, out: &mut dyn TextOut) -> fmt::Result {
        let Some(points) = self else {
            return out.write_str("none");
        };
        for (i, p) in points.iter().enumerate() {
            out.write_str(if i == 0 { "" } else { "," })?;
            p.counts.write(out)?;
            out.write_char(':')?;
            p.deg.write(out)?;
        }
        Ok(())
    }
}

impl Field for bool {
    fn parse(text: &str) -> Option<Self> {
        match text {
            "true" | "on" | "yes" | "1" => Some(true),
            "false" | "off" | "no" | "0" => Some(false),
            _ => None,
        }
    }
    fn write(self, out: &mut dyn TextOut) -> fmt::Result {
        out.write_str(if self { "true" } else { "false" })
    }
}

/// A reference to one field of a [`Config`], by type. Each key only says
/// where its field is; parsing and writing are written once per type here
/// rather than once per key, which keeps the firmware small.
enum Slot<'a> {
    F32(&'a mut f32),
    U8(&'a mut u8),
    U16(&'a mut u16),
    U32(&'a mut u32),
    Bool(&'a mut bool),
    Axes(&'a mut AxisMap),
    CalPoints(&'a mut Option<[CalPoint; 3]>),
}

macro_rules! slot_from {
    ($($t:ty => $variant:ident),+) => {$(
        impl<'a> From<&'a mut $t> for Slot<'a> {
            fn from(field: &'a mut $t) -> Self {
                Self::$variant(field)
            }
        }
    )+};
}
slot_from!(f32 => F32, u8 => U8, u16 => U16, u32 => U32, bool => Bool, AxisMap => Axes,
    Option<[CalPoint; 3]> => CalPoints);

/// Sets `field` from `text`; `false` when it does not parse.
fn set<T: Field>(field: &mut T, text: &str) -> bool {
    T::parse(text).map(|v| *field = v).is_some()
}

impl Slot<'_> {
    fn apply(self, text: &str) -> bool {
        match self {
            Self::F32(f) => set(f, text),
            Self::U8(f) => set(f, text),
            Self::U16(f) => set(f, text),
            Self::U32(f) => set(f, text),
            Self::Bool(f) => set(f, text),
            Self::Axes(f) => set(f, text),
            Self::CalPoints(f) => set(f, text),
        }
    }

    fn write(self, out: &mut dyn TextOut) -> fmt::Result {
        match self {
            Self::F32(f) => f.write(out),
            Self::U8(f) => f.write(out),
            Self::U16(f) => f.write(out),
            Self::U32(f) => f.write(out),
            Self::Bool(f) => f.write(out),
            Self::Axes(f) => f.write(out),
            Self::CalPoints(f) => f.write(out),
        }
    }
}

/// One key of the file: its name, section, and where its field is.
struct Key {
    name: &'static str,
    section: Section,
    slot: fn(&mut Config) -> Slot<'_>,
}

impl Key {
    /// Parses `text` into the field; `false` when it does not parse.
    fn apply(&self, config: &mut Config, text: &str) -> bool {
        (self.slot)(config).apply(text)
    }

    fn show(&self, config: &Config, out: &mut dyn TextOut) -> fmt::Result {
        let mut copy = *config;
        (self.slot)(&mut copy).write(out)
    }
}

/// A key named for its field's path in [`Config`].
macro_rules! key {
    ($section:ident: $($field:ident).+) => {
        Key {
            name: stringify!($($field).+),
            section: Section::$section,
            slot: |config| Slot::from(&mut config.$($field).+),
        }
    };
}

/// Every key, in the order [`Config::write_lines`] writes them. Not keys: the
/// detector's sample rate (the firmware's frame rate), the ADC's range and
/// the IMU's sensitivities (facts of the board, not choices of the rider).
const KEYS: &[Key] = &[
    key!(Wheel: wheel.circumference_m),
    key!(Wheel: wheel.holes),
    key!(Wheel: wheel.timeout_us),
    key!(Wheel: wheel.min_edge_interval_us),
    key!(Wheel: wheel.glitch_fraction),
    key!(Wheel: wheel.window_edges),
    key!(Wheel: wheel.max_window_us),
    key!(Steering: steering.center_counts),
    key!(Steering: steering.deg_per_count),
    key!(Steering: steering.three_point),
    key!(Steering: steering.saturation_margin),
    key!(Imu: imu.axis_map),
    key!(Imu: imu.stuck_samples),
    key!(Detector: detector.window_s),
    key!(Detector: detector.hop_s),
    key!(Detector: detector.bin_lo_hz),
    key!(Detector: detector.bin_hi_hz),
    key!(Detector: detector.bin_spacing_hz),
    key!(Detector: detector.band_lo_hz),
    key!(Detector: detector.band_hi_hz),
    key!(Detector: detector.highpass_hz),
    key!(Detector: detector.amp_on_deg),
    key!(Detector: detector.amp_off_deg),
    key!(Detector: detector.off_hold_s),
    key!(Detector: detector.lookback_s),
    key!(Detector: detector.min_growth_ratio),
    key!(Detector: detector.confirm_hops),
    key!(Detector: detector.impulse_fast_s),
    key!(Detector: detector.impulse_ref_s),
    key!(Detector: detector.impulse_ratio),
    key!(Detector: detector.impulse_min_deg),
    key!(Detector: detector.impulse_holdoff_s),
    key!(Detector: detector.impulse_catchup),
    key!(Detector: detector.impulse_capture_s),
    key!(Detector: detector.max_growth_ratio),
    key!(Detector: detector.freq_window_s),
    key!(Detector: detector.min_speed_mps),
    key!(Detector: detector.harmonic_tol_hz),
    key!(Detector: detector.harmonic_growth_ratio),
    key!(Detector: detector.decay_span_s),
    key!(Detector: detector.decay_span_ratio),
    key!(Detector: detector.decay_trend_s),
    key!(Detector: detector.decay_trend_per_s),
    key!(Alert: alert.enabled),
    key!(Alert: alert.pattern.beep_on_us),
    key!(Alert: alert.pattern.beep_off_us),
    key!(Alert: alert.pattern.min_active_us),
    key!(Alert: alert.margin_mps),
    key!(Alert: alert.approach.beeps),
    key!(Alert: alert.approach.beep_on_us),
    key!(Alert: alert.approach.beep_off_us),
    key!(Alert: alert.approach.period_us),
];

/// Number of `key=value` lines [`Config::write_lines`] produces.
pub const KEY_COUNT: usize = KEYS.len();

/// The boot-mode key: `selftest=1` runs the field self-test at power-on
/// instead of a ride, like holding the marker button. Not a ride setting, so
/// not among [`KEYS`]: the log header never records it.
pub const SELFTEST_KEY: &str = "selftest";

/// The UTF-8 byte order mark.
const UTF8_BOM: &[u8] = b"\xEF\xBB\xBF";

/// Keys of older firmware that are skipped with [`FAULT_OBSOLETE_KEY`].
const OBSOLETE_KEYS: [&str; 1] = ["detector.wheel_circumference_m"];

impl Config {
    /// Reads a `CONFIG.TXT`. Never fails: what cannot be used is reported in
    /// [`Loaded::faults`] and replaced by defaults.
    #[must_use]
    pub fn parse(text: &[u8]) -> Loaded {
        let mut config = Self::default();
        let mut faults = ConfigFaults::default();
        let mut selftest = false;
        // Per section, the last line that set one of its keys (for reports).
        let mut touched: [Option<u16>; SECTIONS.len()] = [None; SECTIONS.len()];
        // A UTF-8 byte order mark (Windows editors write one) is not part
        // of the first key.
        let text = text.strip_prefix(UTF8_BOM).unwrap_or(text);
        for (index, raw) in text.split(|&b| b == b'\n').enumerate() {
            let line_no = u16::try_from(index + 1).unwrap_or(u16::MAX);
            // The comment is cut off as bytes first: whatever its encoding
            // (a Latin-1 `°` from an old editor), it cannot spoil the key.
            let before_comment = raw.split(|&b| b == b'#').next().unwrap_or_default();
            let Ok(line) = core::str::from_utf8(before_comment) else {
                faults.push(line_no, FAULT_UNREADABLE);
                continue;
            };
            let line = line.trim();
            if line.is_empty() {
                continue;
            }
            let Some((name, value)) = line.split_once('=').map(|(k, v)| (k.trim(), v.trim()))
            else {
                faults.push(line_no, FAULT_SYNTAX);
                continue;
            };
            if name.is_empty() {
                faults.push(line_no, FAULT_SYNTAX);
                continue;
            }
            if name == SELFTEST_KEY {
                if !set(&mut selftest, value) {
                    faults.push(line_no, FAULT_BAD_VALUE);
                }
                continue;
            }
            let Some(key) = KEYS.iter().find(|k| k.name == name) else {
                let code = if OBSOLETE_KEYS.contains(&name) {
                    FAULT_OBSOLETE_KEY
                } else {
                    FAULT_UNKNOWN_KEY
                };
                faults.push(line_no, code);
                continue;
            };
            if !key.apply(&mut config, value) {
                faults.push(line_no, FAULT_BAD_VALUE);
                continue;
            }
            touched[key.section as usize] = Some(line_no);
        }
        for (rules, line) in SECTIONS.iter().zip(touched) {
            if !(rules.valid)(&config) {
                (rules.reset)(&mut config);
                faults.push(line.unwrap_or(0), FAULT_REJECTED);
            }
        }
        Loaded {
            config,
            faults,
            selftest,
        }
    }

    /// The wobble detector this configuration runs: its detector settings on
    /// its wheel, the one the speed is measured with.
    ///
    /// # Errors
    /// When the detector settings or the circumference are out of range
    /// (never for a configuration from [`Config::parse`]).
    pub fn detector(&self) -> Result<Detector, DetectorConfigError> {
        Detector::new(self.detector, self.wheel.circumference_m)
    }

    /// Writes the configuration as `key=value` lines, each ending in `\n`,
    /// one per key in a fixed order: what the log header records (one
    /// record per line) and a complete `CONFIG.TXT`. Parsing the text gives
    /// this configuration back exactly. At most [`MAX_TEXT_LEN`] bytes.
    ///
    /// # Errors
    /// When `out` fails (is full).
    pub fn write_lines(&self, out: &mut impl fmt::Write) -> fmt::Result {
        for key in KEYS {
            out.write_str(key.name)?;
            out.write_char('=')?;
            key.show(self, out)?;
            out.write_char('\n')?;
        }
        Ok(())
    }
}

/// Where the configuration in force came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Source {
    /// [`FILE_NAME`] on the card.
    File,
    /// The card has no [`FILE_NAME`]: the defaults, no fault.
    NoFile,
    /// No readable card or volume: the defaults (the logger reports the
    /// card itself).
    NoCard,
}

/// Reads [`FILE_NAME`] from the first volume of the card into `buf` and
/// parses it. A file longer than `buf`, or one whose reading failed part
/// way, is cut after its last whole line read and the rest reported as
/// [`FAULT_UNREADABLE`] (line 0).
pub fn load<
    D: BlockDevice,
    T: TimeSource,
    const DIRS: usize,
    const FILES: usize,
    const VOLUMES: usize,
>(
    volumes: &VolumeManager<D, T, DIRS, FILES, VOLUMES>,
    buf: &mut [u8],
) -> (Loaded, Source) {
    let defaults = |source| (Config::parse(b""), source);
    let Ok(volume) = volumes.open_raw_volume(VolumeIdx(0)) else {
        return defaults(Source::NoCard);
    };
    let read = volumes.open_root_dir(volume).ok().map(|dir| {
        let text = volumes
            .open_file_in_dir(dir, FILE_NAME, Mode::ReadOnly)
            .ok()
            .map(|file| {
                let (len, complete) = read_into(volumes, file, buf);
                let _ = volumes.close_file(file);
                (len, complete)
            });
        let _ = volumes.close_dir(dir);
        text
    });
    let _ = volumes.close_volume(volume);
    match read {
        None => defaults(Source::NoCard),
        Some(None) => defaults(Source::NoFile),
        Some(Some((len, complete))) => {
            let text = buf.get(..len).unwrap_or_default();
            if complete {
                return (Config::parse(text), Source::File);
            }
            let whole_lines = text.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
            let mut loaded = Config::parse(text.get(..whole_lines).unwrap_or_default());
            loaded.faults.push(0, FAULT_UNREADABLE);
            (loaded, Source::File)
        }
    }
}

/// Reads `file` into `buf`; returns the length read and whether that was
/// the whole file. A read error is not the end of the file: what follows
/// it is missing, and the caller reports it.
fn read_into<
    D: BlockDevice,
    T: TimeSource,
    const DIRS: usize,
    const FILES: usize,
    const VOLUMES: usize,
>(
    volumes: &VolumeManager<D, T, DIRS, FILES, VOLUMES>,
    file: embedded_sdmmc::RawFile,
    buf: &mut [u8],
) -> (usize, bool) {
    // A block per call: a read that fails returns nothing of what it had
    // read, so this keeps everything before the failing block.
    const BLOCK: usize = embedded_sdmmc::Block::LEN;
    let mut len = 0;
    while let Some(rest) = buf.get_mut(len..).filter(|r| !r.is_empty()) {
        let chunk = rest.len().min(BLOCK);
        match volumes.read(file, rest.get_mut(..chunk).unwrap_or_default()) {
            Ok(n) if n > 0 => len += n,
            Ok(_) => break,
            Err(_) => return (len, false),
        }
    }
    (len, volumes.file_eof(file).unwrap_or(true))
}

/// One line of the file that was not used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LineFault {
    /// Line number, from 1; 0 for a section rejected with no line of its own.
    pub line: u16,
    /// One of the `FAULT_*` codes of this module.
    pub code: u8,
}

/// What was wrong with a `CONFIG.TXT`: every fault counted per code, the
/// first [`MAX_LINE_FAULTS`] with their line numbers.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ConfigFaults {
    counts: [u16; FAULT_CODES],
    lines: heapless::Vec<LineFault, MAX_LINE_FAULTS>,
}

impl ConfigFaults {
    /// Records a fault with one of the `FAULT_*` codes (others are ignored).
    pub fn push(&mut self, line: u16, code: u8) {
        let Some(count) = usize::from(code)
            .checked_sub(1)
            .and_then(|i| self.counts.get_mut(i))
        else {
            return;
        };
        *count = count.saturating_add(1);
        // Beyond the first few, only the counts are kept.
        let _ = self.lines.push(LineFault { line, code });
    }

    /// No fault at all.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.counts.iter().all(|&c| c == 0)
    }

    /// Faults with `code`.
    #[must_use]
    pub fn count(&self, code: u8) -> u16 {
        usize::from(code)
            .checked_sub(1)
            .and_then(|i| self.counts.get(i))
            .copied()
            .unwrap_or(0)
    }

    /// The first faults, with their line numbers, in file order.
    #[must_use]
    pub fn first(&self) -> &[LineFault] {
        &self.lines
    }

    /// One fault record per code that occurred, stamped `t_us`, with its
    /// count: what the log keeps.
    pub fn records(&self, t_us: u64) -> impl Iterator<Item = Fault> + '_ {
        (1u8..)
            .zip(self.counts)
            .filter(|&(_, count)| count > 0)
            .map(move |(code, count)| Fault {
                t_us,
                source: FaultSource::Config,
                code,
                count,
            })
    }
}

/// A configuration read from a file, with what was wrong with it.
#[derive(Clone, Debug, PartialEq)]
pub struct Loaded {
    /// The configuration in force.
    pub config: Config,
    /// What was skipped or replaced by defaults.
    pub faults: ConfigFaults,
    /// The file asks for the field self-test ([`SELFTEST_KEY`]).
    pub selftest: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text_of(config: &Config) -> String {
        let mut text = String::new();
        config.write_lines(&mut text).expect("String grows");
        text
    }

    #[test]
    fn empty_file_is_the_defaults() {
        let loaded = Config::parse(b"");
        assert_eq!(loaded.config, Config::default());
        assert!(loaded.faults.is_empty());
    }

    #[test]
    fn values_comments_and_whitespace() {
        let text = b"# my bike\r\n\
            wheel.circumference_m = 2.05   # measured\r\n\
            \n\
            detector.amp_on_deg=0.6\n\
            alert.enabled = off\n";
        let loaded = Config::parse(text);
        assert!(loaded.faults.is_empty(), "{:?}", loaded.faults);
        let c = loaded.config;
        assert_eq!(c.wheel.circumference_m, 2.05);
        assert_eq!(c.detector().unwrap().wheel_circumference_m(), 2.05);
        assert_eq!(c.detector.amp_on_deg, 0.6);
        assert!(!c.alert.enabled);
        assert_eq!(c.wheel.holes, WheelConfig::DEFAULT.holes);
    }

    #[test]
    fn a_byte_order_mark_does_not_spoil_the_first_key() {
        // What Windows Notepad saves as "UTF-8 with BOM".
        let loaded = Config::parse(b"\xEF\xBB\xBFwheel.circumference_m=2.05\r\nwheel.holes=36\r\n");
        assert!(loaded.faults.is_empty(), "{:?}", loaded.faults);
        assert_eq!(loaded.config.wheel.circumference_m, 2.05);
        assert_eq!(loaded.config.wheel.holes, 36);
    }

    #[test]
    fn a_comment_in_any_encoding_keeps_its_line_key() {
        // Latin-1 / Windows-1252 `°` (0xB0) and `é` (0xE9): not UTF-8.
        let text = b"steering.center_counts=2100  # \xB0 left, r\xE9gl\xE9\n\
            wheel.holes=36 # UTF-8 is fine too: \xC2\xB0\n\
            # whole-line comment \xE9\n";
        let loaded = Config::parse(text);
        assert!(loaded.faults.is_empty(), "{:?}", loaded.faults);
        assert_eq!(loaded.config.wheel.holes, 36);
        assert_eq!(loaded.config.steering.center_counts, 2100.0);
        // A key or value that is not UTF-8 is still unreadable.
        let loaded = Config::parse(b"wheel.holes=3\xB06\n");
        assert_eq!(loaded.faults.count(FAULT_UNREADABLE), 1);
    }

    #[test]
    fn bad_lines_are_skipped_and_counted_with_line_numbers() {
        let text = b"wheel.holes=36\nno equals sign\nwheel.colour=red\nwheel.holes=-3\n\
            detector.amp_on_deg=nan\n=5\n\xff\xfe\n";
        let loaded = Config::parse(text);
        assert_eq!(loaded.config.wheel.holes, 36);
        assert_eq!(loaded.config.detector, DetectorConfig::DEFAULT);
        let f = &loaded.faults;
        assert_eq!(
            f.first(),
            [
                LineFault {
                    line: 2,
                    code: FAULT_SYNTAX
                },
                LineFault {
                    line: 3,
                    code: FAULT_UNKNOWN_KEY
                },
                LineFault {
                    line: 4,
                    code: FAULT_BAD_VALUE
                },
                LineFault {
                    line: 5,
                    code: FAULT_BAD_VALUE
                },
                LineFault {
                    line: 6,
                    code: FAULT_SYNTAX
                },
                LineFault {
                    line: 7,
                    code: FAULT_UNREADABLE
                },
            ]
        );
        let records: Vec<_> = f.records(7).map(|r| (r.code, r.count)).collect();
        assert_eq!(records, [(1, 2), (2, 1), (3, 2), (5, 1)]);
        assert!(f
            .records(7)
            .all(|r| r.source == FaultSource::Config && r.t_us == 7));
    }

    #[test]
    fn selftest_asks_for_the_field_test_and_leaves_the_ride_settings_alone() {
        let plain = Config::parse(b"wheel.holes=36\n");
        assert!(!plain.selftest);
        for (value, asked) in [("1", true), ("on", true), ("0", false), ("no", false)] {
            let text = format!("wheel.holes=36\nselftest = {value}  # bench\n");
            let loaded = Config::parse(text.as_bytes());
            assert_eq!(loaded.selftest, asked, "selftest={value}");
            assert!(loaded.faults.is_empty(), "{:?}", loaded.faults);
            assert_eq!(loaded.config, plain.config);
        }
        // The header records the ride settings only.
        assert!(!text_of(&Config::default()).contains(SELFTEST_KEY));
    }

    #[test]
    fn a_bad_selftest_value_is_a_counted_fault_and_no_selftest() {
        let loaded = Config::parse(b"selftest=maybe\n");
        assert!(!loaded.selftest);
        assert_eq!(
            loaded.faults.first(),
            [LineFault {
                line: 1,
                code: FAULT_BAD_VALUE
            }]
        );
    }

    #[test]
    fn an_inconsistent_section_falls_back_whole() {
        let text = b"detector.amp_on_deg=0.2\ndetector.amp_off_deg=0.3\nwheel.holes=36\n";
        let loaded = Config::parse(text);
        assert_eq!(loaded.config.detector, DetectorConfig::DEFAULT);
        assert_eq!(loaded.config.wheel.holes, 36);
        assert_eq!(
            loaded.faults.first(),
            [LineFault {
                line: 2,
                code: FAULT_REJECTED
            }]
        );
    }

    #[test]
    fn mounting_and_three_point_calibration() {
        let text = b"imu.axis_map = -y, +x, +z
            steering.three_point = 100:-40, 2048:0.5, 4000:41
";
        let loaded = Config::parse(text);
        assert!(loaded.faults.is_empty(), "{:?}", loaded.faults);
        assert_eq!(
            loaded.config.imu.axis_map,
            AxisMap([SignedAxis::NegY, SignedAxis::PosX, SignedAxis::PosZ])
        );
        let points = loaded.config.steering.three_point.expect("three points");
        assert_eq!(
            points[1],
            CalPoint {
                counts: 2048.0,
                deg: 0.5
            }
        );
        assert_eq!(points[2].deg, 41.0);
    }

    #[test]
    fn a_mirrored_mounting_and_unordered_points_are_rejected() {
        let text = b"imu.axis_map=+y,+x,+z
steering.three_point=3000:0,2000:1,4000:2
";
        let loaded = Config::parse(text);
        assert_eq!(loaded.config.imu, ImuConfig::default());
        assert_eq!(loaded.config.steering, SteeringCalibration::default());
        assert_eq!(
            loaded.faults.first(),
            [
                LineFault {
                    line: 2,
                    code: FAULT_REJECTED
                },
                LineFault {
                    line: 1,
                    code: FAULT_REJECTED
                }
            ]
        );
        let garbled = Config::parse(
            b"imu.axis_map=+x,+y
steering.three_point=1:2,3
",
        );
        assert_eq!(garbled.faults.count(FAULT_BAD_VALUE), 2);
    }

    #[test]
    fn an_old_second_circumference_is_a_counted_fault_and_the_wheel_wins() {
        for text in [
            &b"detector.wheel_circumference_m=2.13\nwheel.circumference_m=2.2\n"[..],
            &b"wheel.circumference_m=2.2\ndetector.wheel_circumference_m=2.13\n"[..],
        ] {
            let loaded = Config::parse(text);
            assert_eq!(loaded.faults.count(FAULT_OBSOLETE_KEY), 1);
            assert_eq!(loaded.faults.count(FAULT_UNKNOWN_KEY), 0);
            assert_eq!(loaded.config.wheel.circumference_m, 2.2);
            let detector = loaded.config.detector().expect("valid");
            assert_eq!(detector.wheel_circumference_m(), 2.2);
        }
        // Alone it leaves the default wheel for both.
        let alone = Config::parse(b"detector.wheel_circumference_m=2.13\n");
        assert_eq!(
            alone.faults.first(),
            [LineFault {
                line: 1,
                code: FAULT_OBSOLETE_KEY
            }]
        );
        assert_eq!(alone.config, Config::default());
        assert_eq!(
            alone
                .config
                .detector()
                .expect("valid")
                .wheel_circumference_m(),
            WheelConfig::DEFAULT.circumference_m
        );
        assert!(!text_of(&alone.config).contains("detector.wheel_circumference_m"));
    }

    #[test]
    fn the_margin_warning_is_configured_and_checked_as_a_section() {
        let loaded = Config::parse(
            b"alert.margin_mps=0.8\nalert.approach.beeps=3\nalert.approach.period_us=2000000\n",
        );
        assert!(loaded.faults.is_empty(), "{:?}", loaded.faults);
        let a = loaded.config.alert;
        assert_eq!((a.margin_mps, a.approach.beeps), (0.8, 3));
        assert_eq!(a.approach.period_us, 2_000_000);
        assert_eq!(Config::default().alert.margin_mps, DEFAULT_MARGIN_MPS);
        // A margin out of range, or a group longer than its period: the
        // alert section falls back whole.
        for text in [
            &b"alert.enabled=false\nalert.margin_mps=-0.1\n"[..],
            b"alert.enabled=false\nalert.margin_mps=6\n",
            b"alert.enabled=false\nalert.approach.beeps=20\n",
        ] {
            let loaded = Config::parse(text);
            assert_eq!(loaded.config.alert, AlertConfig::default());
            assert_eq!(loaded.faults.count(FAULT_REJECTED), 1);
        }
    }

    #[test]
    fn a_zero_hole_wheel_is_rejected() {
        let loaded = Config::parse(b"wheel.holes=0\n");
        assert_eq!(loaded.config.wheel, WheelConfig::DEFAULT);
        assert_eq!(loaded.faults.count(FAULT_REJECTED), 1);
    }

    #[test]
    fn the_lines_round_trip_and_fit() {
        let mut c = Config::default();
        c.wheel.circumference_m = 2.1234567;
        c.detector.amp_on_deg = 0.55;
        c.alert.enabled = false;
        c.alert.margin_mps = 0.35;
        c.alert.approach.beep_on_us = 55_000;
        c.imu.axis_map = AxisMap([SignedAxis::PosZ, SignedAxis::NegY, SignedAxis::PosX]);
        c.steering.three_point = Some([
            CalPoint {
                counts: 12.5,
                deg: -30.25,
            },
            CalPoint {
                counts: 2000.0,
                deg: 0.0,
            },
            CalPoint {
                counts: 4000.0,
                deg: 31.0,
            },
        ]);
        let text = text_of(&c);
        assert_eq!(text.lines().count(), KEY_COUNT);
        let back = Config::parse(text.as_bytes());
        assert!(back.faults.is_empty());
        assert_eq!(back.config, c);
    }

    #[test]
    fn the_widest_values_fit_the_text_bound() {
        let mut c = Config::default();
        let widest_float = "-1.1754942e-38";
        let three_point = [widest_float; 3].map(|f| format!("{f}:{f}")).join(",");
        for key in KEYS {
            // Whichever of these parses as the key's type (no validation).
            let applied = [
                widest_float,
                "4294967295",
                "65535",
                "255",
                "false",
                "-x,-y,-z",
                &three_point,
            ]
            .iter()
            .any(|v| key.apply(&mut c, v));
            assert!(applied, "{}", key.name);
        }
        let text = text_of(&c);
        assert!(text.len() <= MAX_TEXT_LEN, "{} bytes", text.len());
        assert!(text.contains(&three_point));
        let mut bounded = heapless::String::<MAX_TEXT_LEN>::new();
        assert!(c.write_lines(&mut bounded).is_ok());
    }

    #[test]
    fn floats_are_written_short_and_plain_in_the_everyday_range() {
        let text = |v: f32| {
            let mut out = String::new();
            Field::write(v, &mut out).expect("String grows");
            out
        };
        assert_eq!(text(2.18), "2.18");
        assert_eq!(text(-0.25), "-0.25");
        assert_eq!(text(100.0), "100");
        assert_eq!(text(0.0), "0");
        assert_eq!(text(270.0 / 4096.0), "0.06591797");
        assert_eq!(text(0.0001), "0.0001");
        assert_eq!(text(1234567.0), "1234567");
        assert_eq!(text(12345678.0), "1.2345678e7");
        assert_eq!(text(-1.1754942e-38), "-1.1754942e-38");
        assert_eq!(text(f32::MAX), "3.4028235e38");
    }

    #[test]
    fn fault_list_keeps_exact_counts_beyond_its_capacity() {
        let text = "x=1\n".repeat(100);
        let loaded = Config::parse(text.as_bytes());
        assert_eq!(loaded.faults.count(FAULT_UNKNOWN_KEY), 100);
        assert_eq!(loaded.faults.first().len(), MAX_LINE_FAULTS);
    }
}
