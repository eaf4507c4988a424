//! The weave's kicks: the 0.3-1.5 Hz roll and steer oscillation a kick at
//! the saddle (or the bar) sets ringing, measured as the wobble's are
//! ([`super::kicks`]) but in the roll rate, on the weave's time scale.
//!
//! Why the roll rate and not the steering angle: the weave is the
//! bicycle's whole lean and steer swaying together, and the gyroscope's
//! forward axis sees its roll directly, with neither the potentiometer's
//! offset nor the steering the rider adds to balance. A zero-phase
//! band-pass of 0.05-3 Hz keeps the weave and takes out the gyroscope's
//! bias and the wobble.
//!
//! The steps are those of [`super::kicks`], with the weave's scale and
//! three differences, each for a slow ring under slow drifts:
//!
//! - The envelope (over 1 s) is taken of the signal band-passed causally:
//!   a zero-phase filter this slow answers a kick a second and more
//!   before it, so the kick would seem to rise slowly (and be refused as
//!   a growth) and be placed early.
//! - A straight trend is fitted beside the ring
//!   ([`super::sinefit::fit_mode_on_trend`]), no wheel tone: after a kick
//!   the capsize drifts, and the band-pass's answer to the kick's net roll
//!   dies out at a rate like the ring's own; without the trend the
//!   benchmark's weave at 6 m/s came out at -1.40 1/s and 0.96 Hz for
//!   -1.53 and 0.935 (noise-free), with it at -1.53 and 0.935.
//! - The fit also ends where the envelope has fallen to 5 % of its value
//!   at the fit's start: what is left is mostly drift.
//!
//! A kick rises above 3 deg/s within 1.5 s out of 2 s of quiet; the fit
//! starts 0.3 s after the envelope's peak and lasts 1.2-12 s. A kick's
//! amplitude is the roll angle's, the rate's over the ring's angular
//! frequency. A band-pass leaves a decaying sinusoid's frequency and decay
//! as they are (it is an eigenfunction of every linear time-invariant
//! filter); only the kick's own transient is skipped.
//!
//! The stated SD of sigma is the fit's standard error times 2.5 with
//! 0.025 1/s added in quadrature, set on 501 simulated kicks (seeds
//! 300-306, 400-406 and 500-506 of `hil-tests/tests/weave_kicks.rs`: 68 %
//! of the errors within one SD, 93 % within two) and checked on 499 others
//! (seeds 600-806): 64 % within one, 90 % within two. The tails are
//! heavier than a normal distribution's; the margin's robust fit and its
//! between-kick variance take that. The campaigns are riderless Whipple
//! bicycles on a treadmill: the benchmark and BicycleParameters' six,
//! against the model's weave eigenvalue.

use std::path::Path;

use super::kicks::{Band, Kick, KickMode, KickSearch};
use super::run::stream_rows;
use crate::summary::{Summary, SummaryBuilder};
use crate::CliError;

/// The weave's kicks, in the roll rate (deg/s).
pub const WEAVE: Band = Band {
    pass_hz: (0.05, 3.0),
    envelope_window_s: 1.0,
    causal_envelope: true,
    kick_min: 3.0,
    kick_over_background: 4.0,
    quiet_before_s: 2.0,
    max_rise_s: 1.5,
    skip_after_peak_s: 0.3,
    fit_end_over_background: 2.0,
    fit_end_of_start: 0.05,
    max_fit_s: 12.0,
    min_fit_s: 1.2,
    head_s: 2.0,
    freq_band_hz: (0.15, 3.0),
    wheel_tones: false,
    fit_trend: true,
    rate_signal: true,
    // A quarter of the wobble's pieces (10.9 min): every command that
    // analyses a ride runs this search beside the wobble's, and its
    // 20 s overlap is small against it.
    piece_frames: super::kicks::PIECE_FRAMES / 4,
    se_factor: 2.5,
    sd_floor_per_s: 0.025,
};

/// The weave kicks of the log at `path` (in time order) and what `wobblog
/// info` says about the log, read in memory that does not grow with the
/// log: the roll rate goes through a [`KickSearch`] as it streams by.
///
/// # Errors
/// The log cannot be read or has no frames.
pub fn load_weave_kicks(path: &Path) -> Result<(Summary, Vec<Kick>), CliError> {
    let make = |told: &SummaryBuilder| {
        // The wheel's harmonics are not fitted beside a weave: any
        // circumference does.
        KickSearch::for_mode(KickMode::Weave, told.frame_rate_hz(), 1.0)
    };
    let (summary, search) = stream_rows(path, make, |search, row| {
        search.push(row.t_s, row.gyro_dps[0], row.speed_mps);
    })?;
    Ok((summary, search.finish()))
}
