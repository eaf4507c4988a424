//! Simulated weave kick campaigns with a known answer: riderless bicycles
//! of the Whipple model, held upright at their speed as on a treadmill,
//! kicked sideways at the saddle in passes above their weave speed, every
//! pass a card log.
//!
//! The bicycles are the benchmark and BicycleParameters' six measured ones
//! (Moore 2012, `host-tools/bicycle-model/tests/data/bicycleparameters/`),
//! whose weave speeds the model crate reproduces from BicycleParameters'
//! own matrices: weave speeds of 3.5-4.8 m/s, weave frequencies of 0.4-1.5
//! Hz and damping of 0.1-2.5 1/s over the speeds kicked, so the campaigns
//! span bicycles unlike each other and unlike the wobble model the
//! estimators were first written for.
//!
//! - **Motion**: `M q'' + u C1 q' + (g K0 + u^2 K2) q = (T_roll, T_steer)`,
//!   `q = (roll, steer)`, discretised exactly at the frame rate. Above the
//!   capsize speed the capsize grows (up to 0.24 1/s on these bicycles), so
//!   a pass holds one kick and lasts [`PASS_S`]: the bicycle is caught and
//!   set upright between kicks, as on a treadmill.
//! - **Excitation**: the belt's and the air's lateral disturbances as
//!   white roll and steer torques; the kick a roll torque held for
//!   [`KICK_S`], sized for a roll-rate jump of 8-20 deg/s.
//! - **Sensors**: the logger's gyroscope and potentiometer error models
//!   ([`super::sensors`]); the speed the treadmill's, constant.
//! - **Truth**: each kick's weave eigenvalue at its pass's speed, from the
//!   state matrix; the campaign's answer the weave speed
//!   ([`wobble_model::critical_speeds`]).

use std::path::{Path, PathBuf};

use nalgebra::{DMatrix, DVector};
use serde::Serialize;
use wobble_model::eig::eigenvalues;
use wobble_model::simulate::Discrete;
use wobble_model::{critical_speeds, Mode, Model, ParamSet, Sweep};

use super::super::rng::Rng;
use super::sensors::{Channel, GYRO_BIAS_DPS, GYRO_LSB_DPS, GYRO_NOISE_DPS};
use crate::corpus::signal::FS_HZ;

/// The bicycles, by the name of their `*Benchmark.txt`.
pub use wobble_model::params::MEASURED_BICYCLES as BICYCLES;

/// How long a pass lasts, s (its kick 3-4 s in).
pub const PASS_S: f64 = 15.0;
/// How long a kick's roll torque lasts, s.
pub const KICK_S: f64 = 0.1;
/// The roll-rate jump a kick gives, deg/s (either sign).
pub const KICK_RATE_DPS: (f64, f64) = (8.0, 20.0);
/// The disturbances' roll torque, per unit of roll inertia (`M[0][0]`):
/// white, held over a frame, rad/s^2 RMS.
pub const ROLL_NOISE: f64 = 0.08;
/// ... and their steer torque, per unit of the steer inertia.
pub const STEER_NOISE: f64 = 0.08;
/// Steering potentiometer noise, degrees RMS.
const STEER_NOISE_DEG: f64 = 0.05;

/// A campaign's plan.
#[derive(Clone, Debug)]
pub struct Plan {
    /// Speeds kicked at, fractions of the weave speed (slowest, fastest).
    pub fractions: (f64, f64),
    /// Speeds, evenly spread over `fractions`.
    pub steps: usize,
    /// Passes (of one kick each) per speed.
    pub passes_per_step: usize,
}

impl Default for Plan {
    fn default() -> Self {
        Self {
            fractions: (1.1, 1.6),
            steps: 6,
            passes_per_step: 4,
        }
    }
}

/// One kick's truth: the weave eigenvalue at its pass's speed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WeaveKickTruth {
    /// The log it is in (file name).
    pub log: String,
    /// When the kick's torque starts, s since the log's start.
    pub t_s: f64,
    /// Speed, m/s.
    pub speed_mps: f64,
    /// Weave frequency, Hz.
    pub freq_hz: f64,
    /// Weave growth rate (negative: decay), 1/s.
    pub sigma_per_s: f64,
}

/// One pass: its log's name and CSV.
#[derive(Clone, Debug)]
pub struct Pass {
    /// The log's name, without extension.
    pub name: String,
    /// `t_s,steer_deg,speed_mps,ax_g,ay_g,az_g,gx_dps,gy_dps,gz_dps`.
    pub csv: String,
}

/// A simulated weave campaign and its answer.
#[derive(Clone, Debug)]
pub struct Campaign {
    /// The bicycle.
    pub bicycle: String,
    /// The seed it was made from.
    pub seed: u64,
    /// The weave speed, m/s (the answer).
    pub weave_speed_mps: f64,
    /// Every pass, in the order ridden.
    pub passes: Vec<Pass>,
    /// Every kick's truth, in the order ridden.
    pub kicks: Vec<WeaveKickTruth>,
}

/// The parameter file of `bicycle`.
#[must_use]
pub fn params_path(bicycle: &str) -> PathBuf {
    wobble_model::params::measured_bicycle_file(bicycle)
}

/// The Whipple model of `bicycle`.
///
/// # Errors
/// The file does not load.
pub fn model(bicycle: &str) -> Result<Model, String> {
    let set = ParamSet::load(&params_path(bicycle)).map_err(|e| e.to_string())?;
    Model::whipple_of(&set).map_err(|e| e.to_string())
}

/// The weave speed of `model`, m/s: where the weave turns stable.
///
/// # Errors
/// The model has no weave speed below 10 m/s.
pub fn weave_speed_mps(model: &Model) -> Result<f64, String> {
    let speeds: Vec<f64> = (0..=200).map(|i| f64::from(i) * 0.05).collect();
    let sweep = Sweep::run(model, &speeds, |_| {}).map_err(|e| e.to_string())?;
    critical_speeds(model, &sweep)
        .into_iter()
        .find(|c| c.mode == Mode::Weave && !c.unstable_above)
        .map(|c| c.speed_mps)
        .ok_or_else(|| "no weave speed below 10 m/s".into())
}

/// The weave eigenvalue at `speed_mps`: the oscillatory pair's upper
/// member (the Whipple model has one pair above the weave's split).
///
/// # Errors
/// No oscillatory root at that speed.
pub fn weave_at(model: &Model, speed_mps: f64) -> Result<(f64, f64), String> {
    let values = eigenvalues(&model.state_matrix(speed_mps)).ok_or("no eigenvalues")?;
    values
        .iter()
        .filter(|l| l.im > 1e-6)
        .max_by(|a, b| a.im.total_cmp(&b.im))
        .map(|l| (l.re, l.im / std::f64::consts::TAU))
        .ok_or_else(|| format!("no oscillatory root at {speed_mps} m/s"))
}

/// The discrete motion at one speed with roll and steer torque inputs.
fn stepper(model: &Model, speed_mps: f64) -> Result<(Discrete, [f64; 2]), String> {
    let m = model.whipple_matrices().ok_or("not a Whipple model")?.m;
    let m_inv = m.try_inverse().ok_or("singular mass matrix")?;
    let mut b = DMatrix::zeros(4, 2);
    for i in 0..2 {
        for j in 0..2 {
            b[(2 + i, j)] = m_inv[(i, j)];
        }
    }
    let a = model.state_matrix(speed_mps);
    Ok((Discrete::new(&a, &b, 1.0 / FS_HZ), [m[(0, 0)], m[(1, 1)]]))
}

/// The roll rate (deg/s, 15 s at the frame rate) of `model` at
/// `speed_mps` kicked at 3 s by a roll torque giving `kick_dps`, without
/// noise.
///
/// # Errors
/// The model is not a Whipple model.
pub fn ring_down(model: &Model, speed_mps: f64, kick_dps: f64) -> Result<Vec<f64>, String> {
    let (step, [roll_inertia, _]) = stepper(model, speed_mps)?;
    let kick_nm = kick_dps.to_radians() * roll_inertia / KICK_S;
    let mut x = DVector::<f64>::zeros(4);
    let mut out = Vec::new();
    for i in 0..(PASS_S * FS_HZ) as usize {
        let t = i as f64 / FS_HZ;
        let torque = if (3.0..3.0 + KICK_S).contains(&t) {
            kick_nm
        } else {
            0.0
        };
        out.push(x[2].to_degrees());
        x = step.step(&x, &DVector::from_vec(vec![torque, 0.0]));
    }
    Ok(out)
}

/// Simulates `plan` on `bicycle` from `seed`.
///
/// # Errors
/// The bicycle does not load or has no weave speed.
pub fn simulate(bicycle: &str, plan: &Plan, seed: u64) -> Result<Campaign, String> {
    let model = model(bicycle)?;
    let weave_speed = weave_speed_mps(&model).map_err(|e| format!("{bicycle}: {e}"))?;
    let mut rng = Rng::new(seed);
    let mut passes = Vec::new();
    let mut kicks = Vec::new();
    for p in 0..plan.steps * plan.passes_per_step {
        let (lo, hi) = plan.fractions;
        let step_no = p / plan.passes_per_step.max(1);
        let frac = lo + (hi - lo) * step_no as f64 / (plan.steps.max(2) - 1) as f64;
        let speed = weave_speed * frac;
        let (step, [roll_inertia, steer_inertia]) = stepper(&model, speed)?;
        let (sigma, freq) = weave_at(&model, speed)?;
        let name = format!("{bicycle}_s{seed}_p{p:02}");
        let kick_t = 3.0 + rng.range(0.0, 1.0);
        let rate = rng.range(KICK_RATE_DPS.0, KICK_RATE_DPS.1).to_radians();
        let kick_nm = rng.sign() * rate * roll_inertia / KICK_S;
        kicks.push(WeaveKickTruth {
            log: format!("{name}.wbl"),
            t_s: kick_t,
            speed_mps: speed,
            freq_hz: freq,
            sigma_per_s: sigma,
        });
        let mut gyro = Channel::new(rng.fork(1), GYRO_BIAS_DPS, GYRO_NOISE_DPS, GYRO_LSB_DPS);
        let mut pot = Channel::new(rng.fork(2), 1.0, STEER_NOISE_DEG, 0.01);
        let mut noise = rng.fork(3);
        rng.next_u64();
        let mut x = DVector::<f64>::zeros(4);
        let mut csv = String::from("t_s,steer_deg,speed_mps,ax_g,ay_g,az_g,gx_dps,gy_dps,gz_dps\n");
        for i in 0..(PASS_S * FS_HZ) as usize {
            let t = i as f64 / FS_HZ;
            let kick = if (kick_t..kick_t + KICK_S).contains(&t) {
                kick_nm
            } else {
                0.0
            };
            let e = DVector::from_vec(vec![
                kick + roll_inertia * ROLL_NOISE * noise.normal(),
                steer_inertia * STEER_NOISE * noise.normal(),
            ]);
            csv.push_str(&format!(
                "{t:.2},{:.3},{speed:.3},0,0,1,{:.4},0,0\n",
                pot.read(x[1].to_degrees()),
                gyro.read(x[2].to_degrees()),
            ));
            x = step.step(&x, &e);
        }
        passes.push(Pass { name, csv });
    }
    Ok(Campaign {
        bicycle: bicycle.into(),
        seed,
        weave_speed_mps: weave_speed,
        passes,
        kicks,
    })
}

impl Campaign {
    /// Writes every pass as a card log `NAME.wbl` into `dir`, through the
    /// encoder `wobblog encode` uses. Returns the logs' paths.
    ///
    /// # Errors
    /// A file cannot be written.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>, String> {
        self.passes
            .iter()
            .map(|p| super::write_log(dir, &p.name, &p.csv, &format!("{}.csv", p.name), false))
            .collect()
    }
}
