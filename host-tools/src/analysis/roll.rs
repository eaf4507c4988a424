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

use super::filter::contiguous_spans;
use super::run::Run;

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

/// The roll angle of every frame of `run`, degrees. Each span between gaps
/// in the data is estimated on its own.
#[must_use]
pub fn estimate_roll_deg(run: &Run) -> Vec<f64> {
    let mut roll_rad = vec![0.0; run.len()];
    let period_s = 1.0 / run.sample_rate_hz();
    for span in contiguous_spans(&run.t_s, period_s) {
        let forward = pass(run, span.clone(), false);
        let backward = pass(run, span.clone(), true);
        for ((out, f), b) in roll_rad[span].iter_mut().zip(forward).zip(backward) {
            *out = 0.5 * (f + b);
        }
    }
    roll_rad.into_iter().map(f64::to_degrees).collect()
}

/// One pass of the filter over `span`, in time order or reversed; returns
/// the roll in time order, radians.
fn pass(run: &Run, span: std::ops::Range<usize>, reverse: bool) -> Vec<f64> {
    let mut out = vec![0.0; span.len()];
    let order: Box<dyn Iterator<Item = usize>> = if reverse {
        Box::new(span.clone().rev())
    } else {
        Box::new(span.clone())
    };
    let mut roll: Option<f64> = None;
    let mut prev: Option<usize> = None;
    for i in order {
        let r = match (roll, prev) {
            (Some(r), Some(p)) => {
                // The rate at the later of the two frames drives the step
                // in both directions, so the passes integrate the same data.
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
            _ => gravity_reference(run, i, 0.0).unwrap_or(0.0),
        };
        out[i - span.start] = r;
        roll = Some(r);
        prev = Some(i);
    }
    out
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
