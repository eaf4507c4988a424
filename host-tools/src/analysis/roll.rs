//! Roll (lean) angle from the IMU: a complementary filter, run forwards and
//! backwards in time and averaged.
//!
//! Axes: x forward, y left, z up, fixed to the frame; roll is positive when
//! the bicycle leans right.
//!
//! Why a complementary filter and not a Kalman filter: there is one angle and
//! two sources with complementary spectra. The roll-rate gyro is right at
//! high frequency but drifts with its bias; the gravity reference is right
//! on average but shaken by wobble and by the rack's lateral acceleration as
//! the bicycle rocks. One time constant splits the spectrum between them and
//! is easy to reason about; a Kalman filter would need noise covariances that
//! nobody has measured for this bicycle and would settle to the same fixed
//! blend anyway. Offline, the filter runs both ways: the forward pass lags
//! and the backward pass leads by the same amount, and a gyro bias pushes
//! them apart by equal and opposite amounts, so their mean has neither the
//! lag nor the bias error.
//!
//! The gravity reference accounts for turning: in a steady turn the specific
//! force stays in the bicycle's plane and the accelerometer alone would read
//! no lean. With `a_c = v * yaw_rate` the centripetal acceleration, the
//! accelerometer's apparent lean `atan2(f_y, f_z)` is the roll plus
//! `atan2(a_c, g)`, which is subtracted.

use super::filter::follows;
use super::run::Run;
use crate::rows::Row;

/// Standard gravity, m/s².
const G_MPS2: f64 = 9.806_65;
/// Crossover of the complementary filter, s: long enough that the rack's
/// lateral acceleration at weave frequencies (about 1 Hz) is attenuated
/// ten-fold in the reference, short enough that a gyro bias of 1 deg/s
/// moves each pass by only 2 degrees (and their mean by none).
pub const TIME_CONSTANT_S: f64 = 2.0;
/// The gravity reference is used only while the specific force is within
/// this range of 1 g, in g: harder shocks (potholes, kerbs) are not gravity.
const GRAVITY_TOLERANCE_G: f64 = 0.5;

/// Frames the backward pass runs over at a time, beyond its lead.
const CHUNK_FRAMES: usize = 1 << 14;
/// The backward pass over a chunk starts this long after the chunk's end
/// (or at the end of the span, if sooner), s: thirty time constants, after
/// which its guess at the start weighs less than 1e-13.
const BACKWARD_LEAD_S: f64 = 30.0 * TIME_CONSTANT_S;

/// The roll angle of every frame of `run`, degrees. Each span between gaps
/// in the data is estimated on its own.
#[must_use]
pub fn estimate_roll_deg(run: &Run) -> Vec<f64> {
    let mut roll_deg = Vec::with_capacity(run.len());
    let mut stream = RollStream::new(run.sample_rate_hz());
    let mut keep = |_: &Run, _: usize, roll: f64| roll_deg.push(roll);
    for i in 0..run.len() {
        stream.push(run, i, &mut keep);
    }
    stream.finish(&mut keep);
    roll_deg
}

/// The roll estimate of a stream of frames, in memory bounded by
/// [`CHUNK_FRAMES`] and [`BACKWARD_LEAD_S`] whatever the run's length.
///
/// The forward pass runs as frames come; the backward pass needs the
/// future, so each frame's estimate is given once the frames up to
/// [`BACKWARD_LEAD_S`] after it (or the end of its span) are in.
pub struct RollStream {
    period_s: f64,
    chunk: usize,
    lead_frames: usize,
    /// Frames of the current span not yet given (after the last one given,
    /// which the next forward step starts from).
    frames: Run,
    /// The forward pass at each of `frames`, radians.
    forward_rad: Vec<f64>,
    /// How many of `frames` have been given.
    given: usize,
}

impl RollStream {
    /// A stream of frames nominally `fs_hz` apart.
    #[must_use]
    pub fn new(fs_hz: f64) -> Self {
        Self::with_chunk(fs_hz, CHUNK_FRAMES)
    }

    /// A stream whose backward pass runs over `chunk` frames at a time
    /// (tests use other chunks to show that the result does not depend on
    /// them).
    #[must_use]
    pub fn with_chunk(fs_hz: f64, chunk: usize) -> Self {
        Self {
            period_s: 1.0 / fs_hz,
            chunk: chunk.max(1),
            lead_frames: (BACKWARD_LEAD_S * fs_hz).ceil() as usize,
            frames: Run::default(),
            forward_rad: Vec::new(),
            given: 0,
        }
    }

    /// Takes frame `i` of `source`; calls `emit(frames, j, roll_deg)` for
    /// every frame `j` of `frames` whose estimate is now final, in order.
    pub fn push(&mut self, source: &Run, i: usize, emit: &mut impl FnMut(&Run, usize, f64)) {
        self.take(source.t_s[i], |frames| frames.push_from(source, i), emit);
    }

    /// Takes one frame as a row; see [`Self::push`].
    pub fn push_row(&mut self, row: &Row, emit: &mut impl FnMut(&Run, usize, f64)) {
        self.take(row.t_s, |frames| frames.push(row), emit);
    }

    /// Takes the frame at `t_s`, which `add` appends to the frames held.
    fn take(
        &mut self,
        t_s: f64,
        add: impl FnOnce(&mut Run),
        emit: &mut impl FnMut(&Run, usize, f64),
    ) {
        let joins = self
            .frames
            .t_s
            .last()
            .is_some_and(|&t| follows(t, t_s, self.period_s));
        if !joins {
            self.finish(emit);
        }
        add(&mut self.frames);
        let n = self.frames.len();
        let prev = (n > 1).then(|| (self.forward_rad[n - 2], n - 2));
        self.forward_rad.push(step(&self.frames, n - 1, prev));
        if n - self.given >= self.chunk + self.lead_frames {
            self.give(n - self.lead_frames, emit);
        }
    }

    /// Gives every frame still held (the end of the data or of a span).
    pub fn finish(&mut self, emit: &mut impl FnMut(&Run, usize, f64)) {
        self.give(self.frames.len(), emit);
        self.frames.drop_front(self.frames.len());
        self.forward_rad.clear();
        self.given = 0;
    }

    /// Gives frames up to `end`, the backward pass starting from the last
    /// frame held; keeps the last one given for the next forward step.
    fn give(&mut self, end: usize, emit: &mut impl FnMut(&Run, usize, f64)) {
        let n = self.frames.len();
        if end <= self.given {
            return;
        }
        let mut backward_rad = vec![0.0; n - self.given];
        let mut prev = None;
        for i in (self.given..n).rev() {
            let r = step(&self.frames, i, prev);
            backward_rad[i - self.given] = r;
            prev = Some((r, i));
        }
        for i in self.given..end {
            let mean = 0.5 * (self.forward_rad[i] + backward_rad[i - self.given]);
            emit(&self.frames, i, mean.to_degrees());
        }
        let drop = end - 1;
        self.frames.drop_front(drop);
        self.forward_rad.drain(..drop);
        self.given = end - drop;
    }
}

/// One step of the filter to frame `i` from the estimate `prev` at another
/// frame (`None`: the first frame of a pass, started from gravity alone).
fn step(run: &Run, i: usize, prev: Option<(f64, usize)>) -> f64 {
    let Some((r, p)) = prev else {
        return gravity_reference(run, i, 0.0).unwrap_or(0.0);
    };
    // The rate at the later of the two frames drives the step in both
    // directions, so the passes integrate the same data.
    let dt = run.t_s[i] - run.t_s[p];
    let rate = run.gyro_dps[i.max(p)][0].to_radians();
    let predicted = r + rate * dt;
    match gravity_reference(run, i, predicted) {
        Some(reference) => {
            let w = dt.abs() / (TIME_CONSTANT_S + dt.abs());
            predicted + w * (reference - predicted)
        }
        None => predicted,
    }
}

/// The roll that gravity and the turn imply at frame `i`, radians, given
/// the current estimate (to resolve the yaw rate about the vertical).
fn gravity_reference(run: &Run, i: usize, roll_rad: f64) -> Option<f64> {
    let [_, fy, fz] = run.accel_g[i];
    let norm = fy.hypot(fz).hypot(run.accel_g[i][0]);
    if (norm - 1.0).abs() > GRAVITY_TOLERANCE_G {
        return None;
    }
    let [_, wy, wz] = run.gyro_dps[i].map(f64::to_radians);
    let yaw_rate = wz * roll_rad.cos() + wy * roll_rad.sin();
    let centripetal_g = run.speed_mps[i] * yaw_rate / G_MPS2;
    Some(fy.atan2(fz) - centripetal_g.atan2(1.0))
}
