//! Critical speeds: where a mode's real part crosses zero (weave speed,
//! capsize speed, wobble speed), bracketed on a sweep's grid and refined by
//! Brent's method (`roots` crate) on the real part of that mode.

use nalgebra::Complex;
use roots::{find_root_brent, SimpleConvergency};
use serde::Serialize;

use crate::eig::eigenvalues;
use crate::model::Model;
use crate::sweep::{Mode, Sweep};

/// Modes whose crossings are reported.
pub const CRITICAL_MODES: [Mode; 3] = [Mode::Weave, Mode::Capsize, Mode::Wobble];

/// One zero crossing of a mode's real part.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CriticalSpeed {
    /// The mode.
    #[serde(serialize_with = "mode_name")]
    pub mode: Mode,
    /// Where its real part is zero, m/s.
    pub speed_mps: f64,
    /// True if the mode is unstable above this speed (and stable below).
    pub unstable_above: bool,
    /// Its imaginary part there, rad/s.
    pub im_rad_per_s: f64,
}

fn mode_name<S: serde::Serializer>(m: &Mode, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(m.name())
}

/// Brent's tolerance on speed, m/s.
const SPEED_TOL_MPS: f64 = 1e-13;

/// Every crossing of the weave, capsize and wobble modes within the sweep.
#[must_use]
pub fn critical_speeds(model: &Model, sweep: &Sweep) -> Vec<CriticalSpeed> {
    let mut out = Vec::new();
    for mode in CRITICAL_MODES {
        let Some(branch) = sweep.upper(mode) else {
            continue;
        };
        let v = &branch.values;
        for k in 0..v.len().saturating_sub(1) {
            let (a, b) = (v[k], v[k + 1]);
            if a.re == 0.0 || a.re.signum() == b.re.signum() {
                continue;
            }
            let (ua, ub) = (sweep.speeds_mps[k], sweep.speeds_mps[k + 1]);
            // The mode at u: the eigenvalue nearest the straight line
            // between its values at the bracket's ends.
            let at = |u: f64| -> Complex<f64> {
                let t = (u - ua) / (ub - ua);
                let guess = a + (b - a) * t;
                eigenvalues(&model.state_matrix(u))
                    .unwrap_or_default()
                    .into_iter()
                    .min_by(|x, y| (x - guess).norm().total_cmp(&(y - guess).norm()))
                    .unwrap_or(guess)
            };
            let mut conv = SimpleConvergency {
                eps: SPEED_TOL_MPS,
                max_iter: 200,
            };
            if let Ok(u) = find_root_brent(ua, ub, |u| at(u).re, &mut conv) {
                out.push(CriticalSpeed {
                    mode,
                    speed_mps: u,
                    unstable_above: b.re > 0.0,
                    im_rad_per_s: at(u).im.abs(),
                });
            }
        }
    }
    out.sort_by(|a, b| a.speed_mps.total_cmp(&b.speed_mps));
    out
}
