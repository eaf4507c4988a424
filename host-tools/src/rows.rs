//! One row per 100 Hz frame, with the GPS fix in force at that frame: the
//! shape of `wobblog decode` output and of every analysis.

use crate::export::derived::Derived;

use wobble_core::format::{
    FixMode, FrameStatus, GpsFix, Record, ACCEL_COUNTS_PER_G, GYRO_COUNTS_PER_DPS,
    STEER_COUNTS_PER_DEG,
};

mod assembly;

pub use assembly::{Assembly, RowParts, GPS_STALE_US};

/// The GPS columns of a row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpsColumns {
    /// Latitude, degrees.
    pub lat_deg: f64,
    /// Longitude, degrees.
    pub lon_deg: f64,
    /// Speed over ground, m/s, if the receiver sent it.
    pub speed_mps: Option<f64>,
    /// 2D or 3D.
    pub fix: FixMode,
}

impl GpsColumns {
    /// The columns for a fix, `None` if it has no usable position.
    #[must_use]
    pub fn from_fix(fix: &GpsFix) -> Option<Self> {
        if fix.fix == FixMode::None {
            return None;
        }
        Some(Self {
            lat_deg: f64::from(fix.lat_e7?) / 1e7,
            lon_deg: f64::from(fix.lon_e7?) / 1e7,
            speed_mps: fix.speed_cm_s.map(|v| f64::from(v) / 100.0),
            fix: fix.fix,
        })
    }
}

/// One decoded 100 Hz frame in physical units.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Row {
    /// Seconds since boot.
    pub t_s: f64,
    /// Acceleration x/y/z, g.
    pub accel_g: [f64; 3],
    /// Angular rate x/y/z, deg/s.
    pub gyro_dps: [f64; 3],
    /// Steering angle, degrees.
    pub steer_deg: f64,
    /// Wheel speed, m/s.
    pub speed_mps: f64,
    /// Cumulative wheel pulses (wrapping at 2^16).
    pub wheel_count: u16,
    /// Status bits.
    pub status: FrameStatus,
    /// GPS fix in force, if any.
    pub gps: Option<GpsColumns>,
    /// UTC, µs since 1970, from the latest GPS sync pair at or before the
    /// frame (`None` before the first).
    pub utc_us: Option<i64>,
    /// Signals derived from the frames around it, when asked for
    /// ([`crate::export::derived`]).
    pub derived: Derived,
    /// The run it belongs to, where an output names it in every row (a
    /// dataset's frame files); `None` from the decoder.
    pub run: Option<u32>,
}

impl From<&RowParts> for Row {
    fn from(&RowParts { frame, gps, utc_us }: &RowParts) -> Self {
        Self {
            t_s: seconds(frame.t_us),
            accel_g: frame.accel.map(accel_g),
            gyro_dps: frame.gyro.map(gyro_dps),
            steer_deg: steer_deg(frame.steer_cdeg),
            speed_mps: speed_mps(frame.speed_mm_s),
            wheel_count: frame.wheel_count,
            status: frame.status,
            gps,
            utc_us,
            derived: Derived::default(),
            run: None,
        }
    }
}

// A frame's counts in physical units, in f64, so that every stored count
// prints as its exact value (or the shortest decimal that is nearest to
// it). Rows and columns of rows ([`crate::export::frame_columns`]) both
// convert with these.

/// Seconds since boot.
#[must_use]
pub fn seconds(t_us: u64) -> f64 {
    t_us as f64 / 1e6
}

/// Acceleration, g.
#[must_use]
pub fn accel_g(counts: i16) -> f64 {
    f64::from(counts) / f64::from(ACCEL_COUNTS_PER_G)
}

/// Angular rate, deg/s.
#[must_use]
pub fn gyro_dps(counts: i16) -> f64 {
    f64::from(counts) / f64::from(GYRO_COUNTS_PER_DPS)
}

/// Steering angle, degrees.
#[must_use]
pub fn steer_deg(counts: i16) -> f64 {
    f64::from(counts) / f64::from(STEER_COUNTS_PER_DEG)
}

/// Wheel speed, m/s.
#[must_use]
pub fn speed_mps(mm_s: u16) -> f64 {
    f64::from(mm_s) / 1000.0
}

/// Turns a stream of records into rows, in bounded memory (see
/// [`Assembly`] for which fix and which UTC fill a row, and when).
#[derive(Default)]
pub struct RowAssembler {
    assembly: Assembly,
}

impl RowAssembler {
    /// A new assembler.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Takes one record; calls `emit` for every row that is complete (a
    /// few hundred at a time).
    pub fn push(&mut self, record: &Record<'_>, emit: &mut impl FnMut(&Row)) {
        self.assembly
            .push(record, &mut |rows| emit_each(rows, emit));
    }

    /// Emits the rows still held back.
    pub fn finish(&mut self, emit: &mut impl FnMut(&Row)) {
        self.assembly.finish(&mut |rows| emit_each(rows, emit));
    }
}

fn emit_each(rows: &[RowParts], emit: &mut impl FnMut(&Row)) {
    for parts in rows {
        emit(&Row::from(parts));
    }
}
