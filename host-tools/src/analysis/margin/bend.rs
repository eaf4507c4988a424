//! What the line assumes about sigma's bend beyond the kicks, as a shape
//! relative to the wobble speed.
//!
//! Near the wobble speed `u*` sigma is `b (u - u*) + (k/2) (u - u*)^2`. In
//! units of the wobble speed and of the damping at half of it, `D =
//! -sigma(u*/2)`, the bend is the number `beta = k u*^2 / D`: 0 for a
//! straight trend, negative when sigma flattens towards the wobble speed
//! (concave), positive when it steepens (convex); a trend that rises all
//! the way from `u*/2` to `u*` has `-8 < beta < 8` (at -8 it arrives flat,
//! at 8 it leaves `u*/2` flat). The same shape on a bicycle whose wobble
//! speed is twice as high, or whose damping is twice as strong, has the
//! same `beta` but a different `k`: a prior in `beta` carries across
//! bicycles where a prior in 1/s per (m/s)^2 does not.

use serde::Serialize;

/// The allowance the line makes for sigma's bend, judged for each
/// candidate wobble speed in turn. A line fitted by least squares to `a +
/// b u + (d/2) u^2` is off at `u` by exactly `(d/2) ((u - m)^2 - v)`, `m`
/// and `v` the weighted mean and variance of the kicks' speeds (the line
/// absorbs the rest); the kicks are fitted with the prior's bend at the
/// prediction taken out, so the trend is bent by `prior_per_s_mps2`. To
/// ask whether the wobble speed could be `u`, the bend is the shape's
/// curvature *for a wobble speed at `u`* (`beta D / u^2`, `D` the trend's
/// damping at `u/2`): the trend's value there moves by the difference of
/// the two curvatures times that lever, and is uncertain by the shape's SD
/// times it, in quadrature: towards convex bends (which bring the zero
/// closer) where the moved value is still below zero, towards concave ones
/// (which take it further) where it is above. At the prediction the two
/// curvatures agree; below it the allowance grows as `1/u^2`, so a trend
/// that rises slowly cannot claim a high lower bound, and a trend that
/// reaches no zero is judged at each speed on that speed's own scale.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Bend {
    /// Weighted mean speed of the kicks used, m/s.
    pub mean_mps: f64,
    /// Weighted variance of their speeds, (m/s)^2.
    pub variance_mps2: f64,
    /// The curvature the trend is bent by, 1/s per (m/s)^2.
    pub prior_per_s_mps2: f64,
    /// The shape it was taken from.
    pub shape: BendPrior,
}

impl Bend {
    /// Half the lever `(u - m)^2 - v` of a curvature on the line at `u`.
    fn half_lever(&self, u: f64) -> f64 {
        0.5 * ((u - self.mean_mps).powi(2) - self.variance_mps2)
    }

    /// If the wobble speed were `u`, the trend's value there being
    /// `value` and its damping at `u/2` being `damping`: how far the
    /// shape's bend moves the value, and the standard uncertainty it adds
    /// (1/s).
    #[must_use]
    pub fn at(&self, u: f64, value: f64, damping: f64) -> (f64, f64) {
        let (k, sd_convex, sd_concave) = self.shape.curvature(u, damping);
        let lever = self.half_lever(u);
        let shift = (k - self.prior_per_s_mps2) * lever;
        let sd = if value + shift < 0.0 {
            sd_convex
        } else {
            sd_concave
        };
        (shift, sd * lever.abs())
    }
}

/// The line's assumption about the bend: the dimensionless shape `beta`
/// (module documentation) about `mean`, with standard deviation
/// `sd_convex` above it and `sd_concave` below it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct BendPrior {
    /// Mean of `beta`.
    pub mean: f64,
    /// Its standard deviation towards convex shapes (larger `beta`).
    pub sd_convex: f64,
    /// ... towards concave shapes.
    pub sd_concave: f64,
}

impl BendPrior {
    /// The default ([`BEND_SHAPE_MEAN`], [`BEND_SHAPE_SD`]).
    pub const DEFAULT: Self = Self {
        mean: BEND_SHAPE_MEAN,
        sd_convex: BEND_SHAPE_SD_CONVEX,
        sd_concave: BEND_SHAPE_SD_CONCAVE,
    };
    /// The weave's shape in the reciprocal speed ([`super::weave`]):
    /// `beta` of the benchmark and BicycleParameters' six measured
    /// bicycles is 0.3 and 9.3-14.4 (mean 9.1, SD 4.1,
    /// `host-tools/tests/weave_bend.rs`); the prior's mean lies between
    /// the benchmark's and the others', its SD wide enough that each is
    /// within 1.3 SDs of it (the simulated campaigns of the seven:
    /// `hil-tests/tests/weave_kicks.rs`).
    pub const WEAVE: Self = Self {
        mean: 7.0,
        sd_convex: 6.0,
        sd_concave: 6.0,
    };
    /// No bend assumed or allowed for: a straight line.
    pub const NONE: Self = Self {
        mean: 0.0,
        sd_convex: 0.0,
        sd_concave: 0.0,
    };

    /// The curvature, 1/s per (m/s)^2, of `beta` on a trend whose wobble
    /// speed is `zero_mps` and whose damping at half of it is
    /// `damping_per_s` (> 0): `(mean, sd_convex, sd_concave)`.
    #[must_use]
    pub fn curvature(&self, zero_mps: f64, damping_per_s: f64) -> (f64, f64, f64) {
        let unit = damping_per_s.max(0.0) / (zero_mps * zero_mps);
        (
            self.mean * unit,
            self.sd_convex * unit,
            self.sd_concave * unit,
        )
    }
}

/// The mean bend shape `beta` the line assumes (module documentation):
/// the family of bicycles in `host-tools/docs/kick-testing.md` ("The bend
/// prior").
pub const BEND_SHAPE_MEAN: f64 = -1.0;
/// Its standard deviation towards convex shapes.
pub const BEND_SHAPE_SD_CONVEX: f64 = 4.0;
/// Its standard deviation towards concave shapes.
pub const BEND_SHAPE_SD_CONCAVE: f64 = 4.0;
