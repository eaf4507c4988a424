//! One row per 100 Hz frame, with the GPS fix in force at that frame: the
//! shape of `wobblog decode` output and of every analysis.

use crate::export::derived::Derived;
use std::collections::VecDeque;

use wobble_core::format::{
    FixMode, Frame, FrameStatus, GpsFix, Record, UtcSync, ACCEL_COUNTS_PER_G, GYRO_COUNTS_PER_DPS,
    STEER_COUNTS_PER_DEG,
};

/// A GPS fix older than this no longer fills a row's GPS columns.
pub const GPS_STALE_US: u64 = 1_000_000;
/// How long rows wait for a GPS fix stamped before them but written after.
const GPS_WAIT_US: u64 = 500_000;
/// Most rows held back, whatever the frame times say (0.5 s at 100 Hz is
/// 50): times that stand still cannot make the assembler hoard memory.
const MAX_PENDING_ROWS: usize = 4096;

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

impl Row {
    fn new(frame: &Frame, gps: Option<GpsColumns>, sync: Option<UtcSync>) -> Self {
        // In f64, so that every stored count prints as its exact value (or
        // the shortest decimal that is nearest to it).
        let scaled = |c: i16, counts_per_unit: f32| f64::from(c) / f64::from(counts_per_unit);
        Self {
            t_s: frame.t_us as f64 / 1e6,
            accel_g: frame.accel.map(|c| scaled(c, ACCEL_COUNTS_PER_G)),
            gyro_dps: frame.gyro.map(|c| scaled(c, GYRO_COUNTS_PER_DPS)),
            steer_deg: scaled(frame.steer_cdeg, STEER_COUNTS_PER_DEG),
            speed_mps: f64::from(frame.speed_mm_s) / 1000.0,
            wheel_count: frame.wheel_count,
            status: frame.status,
            gps,
            utc_us: sync.and_then(|s| utc_us_at(s, frame.t_us)),
            derived: Derived::default(),
            run: None,
        }
    }
}

/// UTC at local time `t_us` through the pair `sync`, µs since 1970.
fn utc_us_at(sync: UtcSync, t_us: u64) -> Option<i64> {
    let offset_us = i64::try_from(t_us).ok()? - i64::try_from(sync.t_us).ok()?;
    i64::try_from(sync.unix_ms)
        .ok()?
        .checked_mul(1000)?
        .checked_add(offset_us)
}

/// Turns a stream of records into rows, in bounded memory.
///
/// A GPS fix is stamped when its first sentence began, so it reaches the
/// card after frames that come later than it; rows are held back for
/// [`GPS_WAIT_US`] so such a fix still fills them.
#[derive(Default)]
pub struct RowAssembler {
    pending: VecDeque<(u64, Row)>,
    gps: Option<(u64, GpsColumns)>,
    sync: Option<UtcSync>,
}

impl RowAssembler {
    /// A new assembler.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Takes one record; calls `emit` for every row that is complete.
    pub fn push(&mut self, record: &Record<'_>, emit: &mut impl FnMut(&Row)) {
        match record {
            Record::Frame(frame) => {
                // Time going back starts a new segment: nothing waits across
                // it, and a fix from before it fills no row after it.
                if self.pending.back().is_some_and(|&(t, _)| frame.t_us < t) {
                    self.finish(emit);
                    self.gps = None;
                }
                if self.pending.len() >= MAX_PENDING_ROWS {
                    self.emit_first(emit);
                }
                let gps = self.gps_at(frame.t_us);
                let sync = self.sync.filter(|s| s.t_us <= frame.t_us);
                self.pending
                    .push_back((frame.t_us, Row::new(frame, gps, sync)));
                while self
                    .pending
                    .front()
                    .is_some_and(|&(t, _)| t + GPS_WAIT_US < frame.t_us)
                {
                    self.emit_first(emit);
                }
            }
            Record::Gps(fix) => {
                let columns = GpsColumns::from_fix(fix);
                let newer = self.gps.is_none_or(|(t, _)| fix.t_us >= t);
                if newer {
                    self.gps = columns.map(|c| (fix.t_us, c));
                    for (t, row) in &mut self.pending {
                        if *t >= fix.t_us {
                            row.gps = columns.filter(|_| *t - fix.t_us <= GPS_STALE_US);
                        }
                    }
                }
            }
            // Like a fix, a pair is stamped before frames written ahead of it.
            Record::UtcSync(sync) if self.sync.is_none_or(|s| sync.t_us >= s.t_us) => {
                self.sync = Some(*sync);
                for (t, row) in &mut self.pending {
                    if *t >= sync.t_us {
                        row.utc_us = utc_us_at(*sync, *t);
                    }
                }
            }
            _ => {}
        }
    }

    /// Emits the rows still held back.
    pub fn finish(&mut self, emit: &mut impl FnMut(&Row)) {
        for (_, row) in self.pending.drain(..) {
            emit(&row);
        }
    }

    /// Emits the first pending row and drops it (emitted where it lies:
    /// a row is some 200 bytes, and moving each out would copy it).
    fn emit_first(&mut self, emit: &mut impl FnMut(&Row)) {
        if let Some((_, row)) = self.pending.front() {
            emit(row);
        }
        self.pending.pop_front();
    }

    fn gps_at(&self, t_us: u64) -> Option<GpsColumns> {
        let (t, columns) = self.gps?;
        (t <= t_us && t_us - t <= GPS_STALE_US).then_some(columns)
    }
}
