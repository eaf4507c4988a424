//! A linear bicycle model as a pure function: parameters and forward speed
//! to the state matrix `A(u)` of `x' = A x`, with the meaning of each state.

use nalgebra::DMatrix;

use crate::no_slip::{self, NoSlipModel};
use crate::params::{ModelKind, ParamError, ParamSet};
use crate::whipple::{self, Benchmark, WhippleMatrices};
use crate::wobble::{WobbleModel, WobbleParams};

/// What a state is, for telling modes apart by their eigenvectors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StateRole {
    /// Roll angle of the main frame.
    Roll,
    /// Steer angle.
    Steer,
    /// Rider torso roll relative to the main frame.
    Torso,
    /// Steering-head twist.
    Twist,
    /// A tyre's transient slip or camber angle.
    Tyre,
    /// A velocity or rate.
    Rate,
}

/// A state matrix affine in the speed: `A(u) = A0 + u A1`.
#[derive(Clone, Debug, PartialEq)]
pub struct Pencil {
    /// `A(0)`.
    pub a0: DMatrix<f64>,
    /// `dA/du`, per m/s.
    pub a1: DMatrix<f64>,
}

impl Pencil {
    /// `A(u)`.
    #[must_use]
    pub fn at(&self, speed_mps: f64) -> DMatrix<f64> {
        let mut a = self.a0.clone();
        a.zip_apply(&self.a1, |x, y| *x += speed_mps * y);
        a
    }

    /// `A(u)` written row by row into `rows` (`n x n` entries), the same
    /// entries as [`Pencil::at`].
    pub fn write_rows(&self, speed_mps: f64, rows: &mut [f64]) {
        let n = self.a0.nrows();
        let columns = self.a0.as_slice().chunks_exact(n.max(1));
        for (j, (c0, c1)) in columns
            .zip(self.a1.as_slice().chunks_exact(n.max(1)))
            .enumerate()
        {
            for (i, (x, y)) in c0.iter().zip(c1).enumerate() {
                rows[i * n + j] = x + speed_mps * y;
            }
        }
    }
}

/// A linear model ready to evaluate at any speed.
#[derive(Clone, Debug, PartialEq)]
pub enum Model {
    /// The Whipple bicycle (4 states).
    Whipple(WhippleMatrices),
    /// The extended wobble model (14 states).
    Wobble(Box<WobbleModel>),
    /// Its non-holonomic counterpart: no lateral slip at the contacts,
    /// torso and twist free (8 states).
    NoSlip(Box<NoSlipModel>),
}

impl Model {
    /// The model a parameter set describes.
    pub fn from_set(set: &ParamSet) -> Result<Self, ParamError> {
        Ok(match set.model {
            ModelKind::Whipple => Self::Whipple(Benchmark::from_set(set)?.matrices()),
            ModelKind::Wobble => Self::Wobble(Box::new(WobbleModel::from_set(set)?)),
        })
    }

    /// The Whipple model of the same bicycle: the wobble model's bodies
    /// lumped into the benchmark's four (rider locked, head rigid, tyres
    /// without slip).
    pub fn whipple_of(set: &ParamSet) -> Result<Self, ParamError> {
        Ok(match set.model {
            ModelKind::Whipple => Self::Whipple(Benchmark::from_set(set)?.matrices()),
            ModelKind::Wobble => {
                Self::Whipple(WobbleParams::from_set(set)?.to_benchmark().matrices())
            }
        })
    }

    /// The non-holonomic counterpart of the bicycle: its own model for a
    /// Whipple set (which has no slip already), else the wobble model's bodies
    /// and springs with both contacts rolling without lateral slip.
    pub fn no_slip_of(set: &ParamSet) -> Result<Self, ParamError> {
        Ok(match set.model {
            ModelKind::Whipple => Self::Whipple(Benchmark::from_set(set)?.matrices()),
            ModelKind::Wobble => {
                Self::NoSlip(Box::new(NoSlipModel::of(&WobbleModel::from_set(set)?)))
            }
        })
    }

    /// The Whipple matrices, if this is the Whipple model.
    #[must_use]
    pub fn whipple_matrices(&self) -> Option<&WhippleMatrices> {
        match self {
            Self::Whipple(m) => Some(m),
            Self::Wobble(_) | Self::NoSlip(_) => None,
        }
    }

    /// The state matrix at `speed_mps`.
    #[must_use]
    pub fn state_matrix(&self, speed_mps: f64) -> DMatrix<f64> {
        match self {
            Self::Whipple(m) => m.state_matrix(speed_mps),
            Self::Wobble(m) => m.state_matrix(speed_mps),
            Self::NoSlip(m) => m.state_matrix(speed_mps),
        }
    }

    /// The pencil `(A0, A1)` with `A(u) = A0 + u A1`, if the state matrix is
    /// affine in the speed (the wobble model: every speed dependence there is
    /// `u G`, `u / sigma` or `u` times a slip): one multiply-add per entry
    /// per speed instead of assembling the equations.
    #[must_use]
    pub fn pencil(&self) -> Option<Pencil> {
        match self {
            Self::Whipple(_) | Self::NoSlip(_) => None,
            Self::Wobble(m) => {
                let a0 = m.state_matrix(0.0);
                let a1 = m.state_matrix(1.0) - &a0;
                Some(Pencil { a0, a1 })
            }
        }
    }

    /// The states' names, in state order.
    #[must_use]
    pub fn state_names(&self) -> Vec<&'static str> {
        match self {
            Self::Whipple(_) => whipple::STATES.to_vec(),
            Self::Wobble(m) => m.state_names(),
            Self::NoSlip(_) => no_slip::STATES.to_vec(),
        }
    }

    /// The role of each state, in state order.
    #[must_use]
    pub fn state_roles(&self) -> Vec<StateRole> {
        self.state_names()
            .iter()
            .map(|n| match *n {
                "phi" => StateRole::Roll,
                "delta" => StateRole::Steer,
                "phi_r" => StateRole::Torso,
                "beta" => StateRole::Twist,
                n if n.starts_with("alpha") || n.starts_with("gamma") => StateRole::Tyre,
                _ => StateRole::Rate,
            })
            .collect()
    }
}
