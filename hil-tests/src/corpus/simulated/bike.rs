//! The bicycle and its rider as one linear system: the wobble model of a
//! parameter file, closed by a rider who balances it, and the exact
//! discretisation of that system at the sample rate.
//!
//! The rider balances by steering into the fall: a steer torque
//! `T = GAINS . (phi, dphi, delta, ddelta)` reached through a first-order
//! lag of `RIDER_LAG_S` (the neuromuscular delay that keeps a rider's hands
//! out of a 6 Hz wobble), the 15th state, and holds the torso upright with
//! `POSTURE` at the hip. The rider's own steering wander
//! enters the same lag. When a wobble frightens the rider, the hands grip the
//! bar: `GRIP_DAMPING` of steer damping is added (the remedy riders use,
//! and the one that makes the mode stable again).

use std::collections::HashMap;
use std::path::Path;

use nalgebra::{Complex, DMatrix, DVector};
use wobble_model::eig::eigen;
use wobble_model::simulate::Discrete;
use wobble_model::wobble::{WobbleModel, STATES};
use wobble_model::ParamSet;

/// The rider's balance gains from roll (N m/rad), roll rate (N m s/rad),
/// steer (N m/rad) and steer rate (N m s/rad) to the steer torque: found by
/// a search for the gains that make every mode but the wobble decay fastest
/// over 2.5-8 m/s, with no steer-rate gain (which would damp or feed the
/// wobble through the lag). `tests` check the result on both bicycles.
pub const GAINS: [f64; 4] = [12.5, 2.0, -13.0, 0.0];
/// Below [`LOW_SPEED_MPS`] the rider balances harder on roll and steer
/// (found likewise, for 1.9-2.4 m/s, where [`GAINS`] let the bicycle
/// fall): the wobble's growth rate moves by less than 0.01/s and its
/// frequency by less than 0.02 Hz.
pub const LOW_SPEED_GAINS: [f64; 4] = [25.0, 0.0, -14.0, 0.0];
/// See [`LOW_SPEED_GAINS`], m/s.
pub const LOW_SPEED_MPS: f64 = 2.4;
/// The slowest speed the rider balances at, m/s.
pub const MIN_BALANCED_MPS: f64 = 1.9;
/// The rider's lag, s.
pub const RIDER_LAG_S: f64 = 0.1;
/// The rider's active posture: hip stiffness and damping added to the
/// passive ones (the passive 128 N m/rad alone is less than the torso's
/// gravity moment, about 190 N m/rad, so a limp torso would fall), N m/rad
/// and N m s/rad.
pub const POSTURE: (f64, f64) = (200.0, 20.0);
/// Steer damping of gripping hands, N m s/rad.
pub const GRIP_DAMPING: f64 = 2.0;
/// Speeds are rounded to this for the dynamics (a discretisation per
/// speed is cached), m/s.
const SPEED_QUANTUM_MPS: f64 = 0.01;

/// Index of a state of the closed loop.
#[must_use]
pub fn state(name: &str) -> usize {
    STATES
        .iter()
        .position(|s| *s == name)
        .unwrap_or(STATES.len())
}

/// Excitations of the closed loop, in order.
pub const N_INPUTS: usize = 5;
/// Excitation: the rider's steering wander, N m (through the lag).
pub const E_WANDER: usize = 0;
/// Excitation: the rider's hip torque, N m.
pub const E_HIP: usize = 1;
/// Excitation: the road's lateral slope under the front tyre, rad.
pub const E_FRONT: usize = 2;
/// Excitation: the same under the rear tyre, rad.
pub const E_REAR: usize = 3;
/// Excitation: a knock on the handlebar, N m (straight onto the steer).
pub const E_KNOCK: usize = 4;

/// The wobble mode of the closed loop at one speed.
#[derive(Clone, Debug)]
pub struct WobbleMode {
    /// Its eigenvalue (upper member), 1/s and rad/s.
    pub value: Complex<f64>,
    /// Right eigenvector.
    right: DVector<Complex<f64>>,
    /// Left eigenvector, scaled so that `left^H right = 1`.
    left: DVector<Complex<f64>>,
}

impl WobbleMode {
    /// Frequency, Hz.
    #[must_use]
    pub fn freq_hz(&self) -> f64 {
        self.value.im / core::f64::consts::TAU
    }

    /// The steering amplitude the mode holds in state `x`, degrees: the
    /// modal coordinate `q = left^H x` times the steer entry of `2 right`.
    #[must_use]
    pub fn steer_amplitude_deg(&self, x: &DVector<f64>) -> f64 {
        let q: Complex<f64> = self
            .left
            .iter()
            .zip(x.iter())
            .map(|(l, &v)| l.conj() * v)
            .sum();
        (2.0 * q.norm() * self.right[state("delta")].norm()).to_degrees()
    }
}

/// The discretisation at one speed, with the continuous `(A, B)` for the
/// state's derivative.
type Stepper = (Discrete, DMatrix<f64>, DMatrix<f64>);

/// A bicycle with its rider, ready to simulate.
pub struct Bike {
    /// The rider's gains on roll, roll rate, steer, steer rate.
    pub gains: [f64; 4],
    /// The rider's posture `POSTURE`.
    pub posture: (f64, f64),
    model: WobbleModel,
    step_s: f64,
    cache: HashMap<(i64, bool), Stepper>,
    modes: HashMap<(i64, bool), Option<WobbleMode>>,
}

impl Bike {
    /// The bicycle of parameter file `name` (in the model crate's
    /// `params/`), sampled every `step_s`.
    ///
    /// # Errors
    /// The file does not load.
    pub fn new(name: &str, step_s: f64) -> Result<Self, String> {
        Self::from_set(&load_params(name)?, step_s)
    }

    /// The bicycle of a parameter set, sampled every `step_s`.
    ///
    /// # Errors
    /// The set is not a wobble model.
    pub fn from_set(set: &ParamSet, step_s: f64) -> Result<Self, String> {
        let model = WobbleModel::from_set(set).map_err(|e| e.to_string())?;
        Ok(Self {
            gains: GAINS,
            posture: POSTURE,
            model,
            step_s,
            cache: HashMap::new(),
            modes: HashMap::new(),
        })
    }

    /// Wheelbase, m.
    #[must_use]
    pub fn wheelbase_m(&self) -> f64 {
        self.model.params.wheelbase
    }

    /// Number of states of the closed loop.
    #[must_use]
    pub fn n_states(&self) -> usize {
        STATES.len() + 1
    }

    fn key(speed_mps: f64, grip: bool) -> (i64, bool) {
        ((speed_mps / SPEED_QUANTUM_MPS).round() as i64, grip)
    }

    /// `(A, B)` of the closed loop at `speed_mps`, hands gripping or not.
    #[must_use]
    pub fn matrices(&self, speed_mps: f64, grip: bool) -> (DMatrix<f64>, DMatrix<f64>) {
        let u = Self::key(speed_mps, grip).0 as f64 * SPEED_QUANTUM_MPS;
        let n = STATES.len();
        let a0 = self.model.state_matrix(u);
        let b0 = self.model.input_matrix(u);
        let torque = b0.column(0).into_owned();
        let mut a = DMatrix::zeros(n + 1, n + 1);
        a.view_mut((0, 0), (n, n)).copy_from(&a0);
        let hip = b0.column(1).into_owned();
        for i in 0..n {
            a[(i, state("phi_r"))] -= self.posture.0 * hip[i];
            a[(i, state("dphi_r"))] -= self.posture.1 * hip[i];
        }
        if grip {
            let rate = state("ddelta");
            for i in 0..n {
                a[(i, rate)] -= GRIP_DAMPING * torque[i];
            }
        }
        // The rider's torque drives the steer; it follows the command with
        // the rider's lag.
        a.view_mut((0, n), (n, 1)).copy_from(&torque);
        let gains = if u < LOW_SPEED_MPS {
            LOW_SPEED_GAINS
        } else {
            self.gains
        };
        for (k, name) in gains.iter().zip(["phi", "dphi", "delta", "ddelta"]) {
            a[(n, state(name))] = k / RIDER_LAG_S;
        }
        a[(n, n)] = -1.0 / RIDER_LAG_S;
        let mut b = DMatrix::zeros(n + 1, N_INPUTS);
        b[(n, E_WANDER)] = 1.0 / RIDER_LAG_S;
        for (e, col) in [(E_HIP, 1), (E_FRONT, 2), (E_REAR, 3), (E_KNOCK, 0)] {
            b.view_mut((0, e), (n, 1)).copy_from(&b0.column(col));
        }
        (a, b)
    }

    /// One sample step from `x` under the held excitation `e`; returns the
    /// next state and the state's derivative at `x` (for accelerations).
    pub fn step(
        &mut self,
        x: &DVector<f64>,
        e: &DVector<f64>,
        speed_mps: f64,
        grip: bool,
    ) -> (DVector<f64>, DVector<f64>) {
        let key = Self::key(speed_mps, grip);
        if !self.cache.contains_key(&key) {
            let (a, b) = self.matrices(speed_mps, grip);
            let d = Discrete::new(&a, &b, self.step_s);
            self.cache.insert(key, (d, a, b));
        }
        let (d, a, b) = &self.cache[&key];
        (d.step(x, e), a * x + b * e)
    }

    /// The wobble mode of the closed loop at `speed_mps`: the oscillation
    /// between 4 and 11 Hz whose steering dominates its angles.
    pub fn wobble(&mut self, speed_mps: f64, grip: bool) -> Option<WobbleMode> {
        let key = Self::key(speed_mps, grip);
        if let Some(m) = self.modes.get(&key) {
            return m.clone();
        }
        let (a, _) = self.matrices(speed_mps, grip);
        let found = wobble_of(&a);
        self.modes.insert(key, found.clone());
        found
    }
}

/// The parameter file `name` of the model crate's `params/`.
///
/// # Errors
/// The file does not load.
pub fn load_params(name: &str) -> Result<ParamSet, String> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../host-tools/bicycle-model/params")
        .join(name);
    ParamSet::load(&path).map_err(|e| e.to_string())
}

fn wobble_of(a: &DMatrix<f64>) -> Option<WobbleMode> {
    let band = 4.0 * core::f64::consts::TAU..11.0 * core::f64::consts::TAU;
    let angles = ["phi", "phi_r", "delta", "beta"].map(state);
    let right = eigen(a)?.into_iter().find(|e| {
        band.contains(&e.value.im) && {
            let size = |i: usize| e.vector[i].norm();
            angles.iter().all(|&i| size(i) <= size(state("delta")))
        }
    })?;
    // The left eigenvector `w` (`w^H A = lambda w^H`) is the conjugate of
    // the right eigenvector of A^T at the same value.
    let left = eigen(&a.transpose())?
        .into_iter()
        .min_by(|p, q| {
            (p.value - right.value)
                .norm()
                .total_cmp(&(q.value - right.value).norm())
        })?
        .vector
        .map(|c| c.conj());
    // Scaled so that `w^H v = 1`: then `w^H x` is the mode's coordinate.
    let dot: Complex<f64> = left
        .iter()
        .zip(right.vector.iter())
        .map(|(l, r)| l.conj() * r)
        .sum();
    let left = left / dot.conj();
    Some(WobbleMode {
        value: right.value,
        right: right.vector,
        left,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rider balances the test bicycle: below 9 m/s every mode but the
    /// wobble decays, and the wobble keeps the open model's frequency
    /// (within 0.3 Hz) and its sign of growth away from the wobble speed.
    #[test]
    fn the_rider_balances_and_leaves_the_wobble_alone() {
        for file in ["test-bicycle.toml"] {
            let mut bike = Bike::new(file, 0.01).unwrap();
            for u in [2.5, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0] {
                let (a, _) = bike.matrices(u, false);
                let wobble = bike.wobble(u, false).unwrap();
                let open = wobble_model::eig::eigenvalues(&bike.model.state_matrix(u)).unwrap();
                let open = open
                    .iter()
                    .filter(|c| c.im > 30.0 && c.im < 45.0)
                    .min_by(|p, q| {
                        (**p - wobble.value)
                            .norm()
                            .total_cmp(&(**q - wobble.value).norm())
                    })
                    .unwrap();
                assert!(
                    (open.im - wobble.value.im).abs() < 0.3 * core::f64::consts::TAU,
                    "{file} {u}"
                );
                if open.re.abs() > 0.2 {
                    assert_eq!(
                        open.re > 0.0,
                        wobble.value.re > 0.0,
                        "{file} {u}: {open} {}",
                        wobble.value
                    );
                }
                for ev in wobble_model::eig::eigenvalues(&a).unwrap() {
                    if (ev - wobble.value).norm() > 1e-6 && (ev - wobble.value.conj()).norm() > 1e-6
                    {
                        assert!(ev.re < -0.3, "{file} at {u} m/s: {ev}");
                    }
                }
                // Gripping hands make the wobble stable; the rest grows
                // slowly enough for the second or two the rider grips.
                assert!(bike.wobble(u, true).unwrap().value.re < -1.0, "{file} {u}");
                let (a, _) = bike.matrices(u, true);
                for ev in wobble_model::eig::eigenvalues(&a).unwrap() {
                    assert!(ev.re < 0.5, "{file} at {u} m/s, gripping: {ev}");
                }
            }
        }
    }

    /// Down to the slowest balanced speed the rider's harder low-speed
    /// gains keep every mode but the wobble decaying, and the wobble where
    /// the usual gains have it.
    #[test]
    fn the_rider_balances_slowly_too() {
        let mut bike = Bike::new("test-bicycle.toml", 0.01).unwrap();
        let mut u = MIN_BALANCED_MPS;
        while u < LOW_SPEED_MPS {
            let (a, _) = bike.matrices(u, false);
            let wobble = bike.wobble(u, false).unwrap().value;
            for ev in wobble_model::eig::eigenvalues(&a).unwrap() {
                if (ev - wobble).norm() > 1e-6 && (ev - wobble.conj()).norm() > 1e-6 {
                    assert!(ev.re < -0.05, "at {u} m/s: {ev}");
                }
            }
            // The usual gains at this speed (they would let it fall).
            let mut usual = a.clone();
            for (k, name) in GAINS.iter().zip(["phi", "dphi", "delta", "ddelta"]) {
                usual[(STATES.len(), state(name))] = k / RIDER_LAG_S;
            }
            let other = wobble_of(&usual).unwrap().value;
            assert!(
                (other.re - wobble.re).abs() < 0.01 && (other.im - wobble.im).abs() < 0.1,
                "at {u} m/s: {other} vs {wobble}"
            );
            u += 0.1;
        }
    }
}
