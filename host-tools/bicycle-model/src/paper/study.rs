//! A bicycle and its changed versions, each evaluated once: the figures
//! the claims of [`super::CLAIMS`] read, cached by the change's name.

use std::collections::HashMap;

use crate::model::Model;
use crate::params::{ParamError, ParamSet};
use crate::sweep::{Mode, SweepError};

use super::figures::{grid, Figures};
use super::variation;

/// Why a study could not evaluate a claim.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum StudyError {
    /// A changed parameter set is not a bicycle.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// The eigenvalues could not be computed.
    #[error(transparent)]
    Sweep(#[from] SweepError),
}

/// A bicycle under study: its parameter set and the figures of every
/// changed version asked for so far.
pub struct Study {
    base: ParamSet,
    light_rider_kg: f64,
    speeds: Vec<f64>,
    cache: HashMap<String, Figures>,
}

/// The speeds of a study's sweeps: 0 to 14 m/s every 0.1 m/s for the
/// claims table, coarser in a search.
pub const TABLE_STEP_MPS: f64 = 0.1;

impl Study {
    /// The study of `base` on sweeps every `step_mps` from 0 to 14 m/s; the
    /// light rider weighs `light_rider_kg`.
    #[must_use]
    pub fn new(base: &ParamSet, light_rider_kg: f64, step_mps: f64) -> Self {
        Self {
            base: base.clone(),
            light_rider_kg,
            speeds: grid(step_mps),
            cache: HashMap::new(),
        }
    }

    /// The bicycle studied.
    #[must_use]
    pub fn base(&self) -> &ParamSet {
        &self.base
    }

    /// The light rider's mass, kg.
    #[must_use]
    pub fn light_rider_kg(&self) -> f64 {
        self.light_rider_kg
    }

    /// The figures of the version `name`, built by `change` from the base
    /// the first time, with tyres (`no_slip` false) or on non-holonomic
    /// contacts.
    fn figures(
        &mut self,
        name: &str,
        no_slip: bool,
        change: impl FnOnce(&ParamSet) -> Result<ParamSet, ParamError>,
    ) -> Result<&Figures, StudyError> {
        let key = format!("{name}{}", if no_slip { " (no slip)" } else { "" });
        if !self.cache.contains_key(&key) {
            let set = change(&self.base)?;
            let model = if no_slip {
                Model::no_slip_of(&set)?
            } else {
                Model::from_set(&set)?
            };
            let f = Figures::of(&model, &self.speeds)?;
            self.cache.insert(key.clone(), f);
        }
        Ok(&self.cache[&key])
    }

    /// The bicycle as it is.
    ///
    /// # Errors
    /// When the set is not a wobble-model bicycle, or its sweep fails.
    pub fn bicycle(&mut self) -> Result<&Figures, StudyError> {
        self.figures("as it is", false, |s| Ok(s.clone()))
    }

    /// Its non-holonomic counterpart (the paper's Figure 4 thick line).
    ///
    /// # Errors
    /// As [`Self::bicycle`].
    pub fn no_slip(&mut self) -> Result<&Figures, StudyError> {
        self.figures("as it is", true, |s| Ok(s.clone()))
    }

    /// Each key scaled by `factor`.
    ///
    /// # Errors
    /// When a key is not in the set, or the sweep fails.
    pub fn scaled(&mut self, keys: &[&str], factor: f64) -> Result<&Figures, StudyError> {
        let changes: Vec<(&str, f64)> = keys.iter().map(|k| (*k, factor)).collect();
        self.figures(&format!("{keys:?} x{factor}"), false, |s| {
            variation::scaled(s, &changes)
        })
    }

    /// A point mass added to the body of `section`.
    ///
    /// # Errors
    /// As [`Self::scaled`].
    pub fn loaded(
        &mut self,
        section: &str,
        kg: f64,
        x: f64,
        z: f64,
    ) -> Result<&Figures, StudyError> {
        self.figures(&format!("{kg} kg on {section}"), false, |s| {
            variation::loaded(s, section, kg, x, z)
        })
    }

    /// The front tyre made heavier, its spin inertia times `factor`.
    ///
    /// # Errors
    /// As [`Self::scaled`].
    pub fn heavier_front_tyre(&mut self, factor: f64) -> Result<&Figures, StudyError> {
        self.figures(&format!("front tyre spin x{factor}"), false, |s| {
            variation::heavier_front_tyre(s, factor)
        })
    }

    /// The light rider.
    ///
    /// # Errors
    /// As [`Self::scaled`]; the set needs `[rider_legs]`.
    pub fn light_rider(&mut self) -> Result<&Figures, StudyError> {
        let kg = self.light_rider_kg;
        self.figures("light rider", false, |s| variation::rider_of_mass(s, kg))
    }

    /// The rider moved forward by `dx` m.
    ///
    /// # Errors
    /// As [`Self::scaled`].
    pub fn rider_moved(&mut self, dx: f64) -> Result<&Figures, StudyError> {
        self.figures(&format!("rider {dx:+} m"), false, |s| {
            variation::rider_moved(s, dx)
        })
    }

    /// The steer axis `deg` further from vertical.
    ///
    /// # Errors
    /// As [`Self::scaled`].
    pub fn head_angle(&mut self, deg: f64) -> Result<&Figures, StudyError> {
        self.figures(&format!("steer axis {deg:+} deg"), false, |s| {
            variation::head_angle(s, deg)
        })
    }
}

/// The wobble frequency of `f` at the speeds where frequencies are
/// compared (4, 8 and 12 m/s), Hz.
#[must_use]
pub fn wobble_hz(f: &Figures) -> [f64; 3] {
    [4.0, 8.0, 12.0].map(|u| f.hz(Mode::Wobble, u))
}
