//! Linear bicycle models, host-only: parameter sets with units and sources,
//! the Whipple benchmark bicycle (Meijaard et al. 2007) and the extended
//! wobble model, each a pure function from parameters and forward speed to
//! a state matrix; on top of it eigenvalues against speed, modes followed
//! across speed, and critical speeds; and their response in time.
#![warn(missing_docs)]

pub mod critical;
pub mod eig;
pub mod fit;
mod hessenberg_qr;
pub mod model;
pub mod multibody;
mod naming;
pub mod neutral;
pub mod no_slip;
pub mod paper;
pub mod params;
pub mod simulate;
pub mod sweep;
pub mod synthetic;
mod track;
pub mod whipple;
pub mod wobble;

pub use critical::{critical_speeds, CriticalSpeed};
pub use model::{Model, Pencil, StateRole};
pub use nalgebra::Complex;
pub use params::{ModelKind, ParamError, ParamSet, Problem, Quantity, Unit};
pub use sweep::{Branch, Mode, Survey, Sweep, SweepError};
