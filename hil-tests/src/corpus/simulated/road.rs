//! The road's lateral irregularity under the tyres, with the displacement
//! spectrum of ISO 8608 (2016), "Mechanical vibration: Road surface
//! profiles", Table 1: `G_d(n) = G_d(n0) (n / n0)^-2` with `n0 = 0.1
//! cycles/m`, `G_d(n0) = 16e-6 m^3` for class A and `64e-6 m^3` for class B
//! (the geometric means of the classes), over `0.011 <= n <= 2.83 cycles/m`.
//!
//! The linear model has no vertical motion, so the spectrum is applied to
//! the lateral line the tyres follow (the ruts and camber changes a tyre is
//! steered by), scaled by [`LATERAL_RATIO`]; what the model takes is its
//! slope `dy/ds`, added to each tyre's slip angle. With the exponent 2 the slope spectrum is flat:
//! `(2 pi n)^2 G_d(n) = 4 pi^2 G_d(n0) n0^2`, so the slope is white noise in
//! distance, band-limited at 2.83 cycles/m. The rear tyre rolls over the
//! same line a wheelbase later.

use super::super::rng::Rng;

/// The lateral line's amplitude against the standard's vertical profile.
/// An assumption, not a published figure (ISO 8608 classifies vertical
/// profiles only): at the full vertical level a class B road alone would
/// hold the wobble mode at 1-4 degrees below the wobble speed, which riders
/// do not feel; a tenth keeps it at 0.02-0.2 degrees.
pub const LATERAL_RATIO: f64 = 0.1;
/// Reference spatial frequency, cycles/m.
const N0_PER_M: f64 = 0.1;
/// Highest spatial frequency of the standard's classification, cycles/m.
const N_MAX_PER_M: f64 = 2.83;
/// Grid of the generated line, m: samples at twice the highest frequency.
const STEP_M: f64 = 1.0 / (2.0 * N_MAX_PER_M);

/// An ISO 8608 road class.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RoadClass {
    /// Very good (new asphalt).
    A,
    /// Good.
    B,
}

impl RoadClass {
    /// `G_d(n0)`, m^3 (ISO 8608 Table 1, geometric mean of the class).
    #[must_use]
    pub fn gd_n0_m3(self) -> f64 {
        match self {
            Self::A => 16e-6,
            Self::B => 64e-6,
        }
    }

    /// The class letter.
    #[must_use]
    pub fn letter(self) -> char {
        match self {
            Self::A => 'A',
            Self::B => 'B',
        }
    }

    /// RMS slope of the band-limited line, rad: the flat slope spectrum
    /// `4 pi^2 G_d(n0) n0^2` (one-sided) integrated up to the band edge.
    #[must_use]
    pub fn slope_rms_rad(self) -> f64 {
        let level = 4.0 * core::f64::consts::PI.powi(2) * self.gd_n0_m3() * N0_PER_M * N0_PER_M;
        libm::sqrt(level * N_MAX_PER_M)
    }
}

/// The slope of one road's lateral line along its length.
#[derive(Clone, Debug)]
pub struct Road {
    slope_rad: Vec<f64>,
}

impl Road {
    /// `length_m` of class `class` road drawn from `rng`.
    #[must_use]
    pub fn new(class: RoadClass, length_m: f64, rng: &mut Rng) -> Self {
        let n = (length_m / STEP_M) as usize + 2;
        // White samples at spacing `STEP_M` carry a flat one-sided spectrum of
        // 2 sigma^2 STEP_M up to 1 / (2 STEP_M) = N_MAX.
        let sigma = LATERAL_RATIO * class.slope_rms_rad();
        Self {
            slope_rad: (0..n).map(|_| sigma * rng.normal()).collect(),
        }
    }

    /// The slope at distance `s_m` (linear between grid points; 0 before
    /// the start and past the end).
    #[must_use]
    pub fn slope_at(&self, s_m: f64) -> f64 {
        if s_m < 0.0 {
            return 0.0;
        }
        let x = s_m / STEP_M;
        let i = x as usize;
        match (self.slope_rad.get(i), self.slope_rad.get(i + 1)) {
            (Some(a), Some(b)) => a + (b - a) * (x - i as f64),
            _ => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The generated slope has the class's variance, the level ISO 8608's
    /// `G_d(n0)` gives.
    #[test]
    fn slope_has_the_class_level() {
        let mut rng = Rng::new(7);
        for class in [RoadClass::A, RoadClass::B] {
            let road = Road::new(class, 20_000.0, &mut rng);
            let n = road.slope_rad.len() as f64;
            let ms = road.slope_rad.iter().map(|s| s * s).sum::<f64>() / n;
            let want = (LATERAL_RATIO * class.slope_rms_rad()).powi(2);
            assert!((ms / want - 1.0).abs() < 0.03, "{ms} vs {want}");
        }
        // Class B is twice class A in amplitude (four times in G_d).
        assert!((RoadClass::B.slope_rms_rad() / RoadClass::A.slope_rms_rad() - 2.0).abs() < 1e-12);
        // 2 pi sqrt(16e-6 * 0.01 * 2.83) = 4.23 mrad for class A.
        assert!((RoadClass::A.slope_rms_rad() - 4.23e-3).abs() < 0.01e-3);
    }
}
