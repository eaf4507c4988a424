//! Host-side test support of the wobble logger: the synthetic corpus
//! (signal models, the deterministic generator and its ground truth) and the
//! detector metrics that score the on-board detector against it.
//!
//! The QEMU harness will live here too, as its own module.
#![warn(missing_docs)]

pub mod corpus;
pub mod kick_metrics;
pub mod margin_stress;
pub mod metrics;
pub mod qemu;
