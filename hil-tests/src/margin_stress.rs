//! Stress campaigns for the margin prediction: kick-test campaigns drawn
//! at the level of the kicks (each kick's speed, true growth rate and
//! measured growth rate with its stated SD), from bicycles whose sigma
//! against speed has shapes the prediction was not built on, with the
//! kick-to-kick scatter of the true damping, outliers and speed drift;
//! and the scores of the host's estimate (`wobblog::analysis::margin`)
//! and the board's (`wobble_core::detector::MarginWarning`) on them.
//!
//! A campaign's sigma is `D h(u / u*)`: `u*` the wobble speed, `D` the
//! damping at half of it, and `h(x) = p (x - 1) + (beta / 2) (x - 1)^2`
//! with `h(1/2) = -1` (so `p = 2 + beta / 4`): `beta` is the bend shape of
//! `wobblog::analysis::margin::bend`. The low-speed class has sigma
//! falling with speed through the kicks (a wobble unstable below them and
//! stable above): no wobble speed may be claimed ahead.

use crate::corpus::rng::Rng;
use wobble_core::config::DEFAULT_MARGIN_MPS;
use wobble_core::detector::{Kick, MarginWarning, SIGMA_SD_FLOOR_PER_S, SIGMA_SE_FACTOR};
use wobblog::analysis::margin::{predict_bent, BendPrior, KickPoint, Margin, Trend};

/// The shape of sigma against speed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Shape {
    /// `beta = 0`.
    Straight,
    /// `beta = -1`, as sigma bends on this project's own bicycle model.
    OurModel,
    /// `beta = +3`: sigma steepens towards the wobble speed.
    Convex,
    /// `beta = -3`.
    Concave,
    /// `beta = -7`: sigma arrives at zero with an eighth of its slope at
    /// half the wobble speed.
    FlatAtCrossing,
    /// sigma falls with speed through the kicks: stable above them.
    LowSpeedWobble,
}

impl Shape {
    /// Every class.
    pub const ALL: [Self; 6] = [
        Self::Straight,
        Self::OurModel,
        Self::Convex,
        Self::Concave,
        Self::FlatAtCrossing,
        Self::LowSpeedWobble,
    ];

    /// The bend shape `beta` (none for the low-speed class).
    #[must_use]
    pub fn beta(self) -> Option<f64> {
        match self {
            Self::Straight => Some(0.0),
            Self::OurModel => Some(-1.0),
            Self::Convex => Some(3.0),
            Self::Concave => Some(-3.0),
            Self::FlatAtCrossing => Some(-7.0),
            Self::LowSpeedWobble => None,
        }
    }

    /// Its name in the tables.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Straight => "straight",
            Self::OurModel => "bent as our model (beta -1)",
            Self::Convex => "convex (beta +3)",
            Self::Concave => "concave (beta -3)",
            Self::FlatAtCrossing => "flat at the crossing (beta -7)",
            Self::LowSpeedWobble => "unstable below the kicks, stable above",
        }
    }
}

/// What a campaign is drawn from.
#[derive(Clone, Copy, Debug)]
pub struct Recipe {
    /// The shape.
    pub shape: Shape,
    /// Kick-to-kick SD of the true damping, 1/s: drawn from this range.
    pub scatter_per_s: (f64, f64),
    /// Kicks: drawn from this range (inclusive).
    pub kicks: (usize, usize),
    /// Whether some campaigns carry outliers (a hand grabbing the bar, a
    /// ring locked to a wheel harmonic).
    pub outliers: bool,
    /// Whether the speed drifts during ring-downs.
    pub drift: bool,
}

impl Recipe {
    /// The acceptance's campaigns of `shape`: scatter 0.12 1/s, 6 to 40
    /// kicks, outliers and drift.
    #[must_use]
    pub fn acceptance(shape: Shape) -> Self {
        Self {
            shape,
            scatter_per_s: (0.12, 0.12),
            kicks: (6, 40),
            outliers: true,
            drift: true,
        }
    }

    /// The whole stress range of `shape`: scatter 0.04-0.15 1/s.
    #[must_use]
    pub fn wide(shape: Shape) -> Self {
        Self {
            scatter_per_s: (0.04, 0.15),
            ..Self::acceptance(shape)
        }
    }
}

/// One campaign: its kicks and its truth.
#[derive(Clone, Debug)]
pub struct Campaign {
    /// The true wobble speed, m/s (`None`: none above the kicks).
    pub wobble_speed_mps: Option<f64>,
    /// The kicks as measured.
    pub kicks: Vec<KickPoint>,
}

/// Draws the campaign of `recipe` with `seed`.
#[must_use]
pub fn campaign(recipe: &Recipe, seed: u64) -> Campaign {
    let mut rng = Rng::new(seed ^ 0x6d61_7267_696e);
    let wobble = rng.range(2.5, 7.0);
    let damping = rng.range(0.6, 2.0);
    let tau = rng.range(recipe.scatter_per_s.0, recipe.scatter_per_s.1);
    let n =
        recipe.kicks.0 + (rng.next_u64() % (recipe.kicks.1 - recipe.kicks.0 + 1) as u64) as usize;
    // The kicks' speeds: from about 0.45 to about 0.85 of the wobble speed.
    let (from, to) = (rng.range(0.4, 0.5), rng.range(0.75, 0.9));
    // Stated SDs, and how much larger the real measurement error is.
    let understated = rng.range(1.0, 1.5);
    let drift = if recipe.drift {
        rng.range(0.0, 0.3)
    } else {
        0.0
    };
    let truth = |u: f64| -> f64 {
        match recipe.shape.beta() {
            Some(beta) => {
                let (x, p) = (u / wobble - 1.0, 2.0 + beta / 4.0);
                damping * (p * x + 0.5 * beta * x * x)
            }
            // Stable above 0.35 u*, more so with speed, levelling off.
            None => -damping * (0.2 + 1.6 * (u / wobble - 0.35)).min(1.6),
        }
    };
    let mut kicks: Vec<KickPoint> = (0..n)
        .map(|_| {
            let u = wobble * rng.range(from, to);
            let sd = rng.range(0.03, 0.12);
            let sigma = truth(u) + tau * rng.normal() + understated * sd * rng.normal();
            // The speed the ring-down reports: its mean over a drifting
            // ride, off by up to half the drift from the speed the damping
            // belongs to.
            let reported = u + 0.5 * drift * rng.range(-1.0, 1.0);
            KickPoint {
                speed_mps: reported,
                sigma_per_s: sigma,
                sigma_sd_per_s: sd,
                freq_hz: 7.0,
            }
        })
        .collect();
    if recipe.outliers && rng.uniform() < 0.5 {
        let bad = 1 + (rng.next_u64() % 2) as usize;
        for _ in 0..bad {
            let i = (rng.next_u64() % n as u64) as usize;
            if rng.uniform() < 0.5 {
                // A hand on the bar: the ring dies fast.
                kicks[i].sigma_per_s -= rng.range(1.5, 4.0);
            } else {
                // A ring locked to a wheel harmonic: barely decaying.
                kicks[i].sigma_per_s = -rng.range(0.0, 0.1);
            }
            kicks[i].sigma_sd_per_s = rng.range(0.03, 0.06);
        }
    }
    Campaign {
        wobble_speed_mps: recipe.shape.beta().map(|_| wobble),
        kicks,
    }
}

/// One campaign's prediction as scored.
#[derive(Clone, Copy, Debug, Default)]
pub struct Outcome {
    /// Both ends of the interval bounded.
    pub closed: bool,
    /// Closed and holding the truth.
    pub covered: bool,
    /// The lower bound over the truth less 1 (none without either).
    pub lower_excess: Option<f64>,
    /// The riding limit over the truth less 1.
    pub ride_excess: Option<f64>,
    /// The point estimate's relative error.
    pub error: Option<f64>,
    /// A closed interval's width over the truth.
    pub width: Option<f64>,
    /// A wobble speed claimed where there is none ahead (a point
    /// estimate or a closed interval).
    pub false_claim: bool,
}

/// Scores the host's prediction `m` of campaign `c`.
#[must_use]
pub fn score(c: &Campaign, m: &Margin) -> Outcome {
    score_parts(
        c.wobble_speed_mps,
        m.wobble_speed_mps,
        m.ci95_mps,
        m.advice.ride_below_mps,
    )
}

/// Scores a prediction given by its parts.
#[must_use]
pub fn score_parts(
    truth: Option<f64>,
    estimate: Option<f64>,
    ci: [Option<f64>; 2],
    ride_below: Option<f64>,
) -> Outcome {
    let closed = ci.iter().all(Option::is_some);
    let Some(t) = truth else {
        return Outcome {
            closed,
            false_claim: estimate.is_some() || closed,
            ..Outcome::default()
        };
    };
    Outcome {
        closed,
        covered: matches!(ci, [Some(lo), Some(hi)] if lo <= t && t <= hi),
        lower_excess: ci[0].map(|lo| lo / t - 1.0),
        ride_excess: ride_below.map(|r| r / t - 1.0),
        error: estimate.map(|e| e / t - 1.0),
        width: match ci {
            [Some(lo), Some(hi)] => Some((hi - lo) / t),
            _ => None,
        },
        false_claim: false,
    }
}

/// The host's outcomes on `campaigns` campaigns of `recipe` from seed
/// `first` on, the line assuming `prior`.
#[must_use]
pub fn host_outcomes(
    recipe: &Recipe,
    prior: BendPrior,
    first: u64,
    campaigns: u64,
) -> Vec<Outcome> {
    (first..first + campaigns)
        .map(|seed| {
            let c = campaign(recipe, seed);
            score(&c, &predict_bent(&c.kicks, Trend::Line, prior))
        })
        .collect()
}

/// The board's outcomes (`MarginWarning`, its latest 24 kicks, `f32`) on
/// the same campaigns: each kick given the fit error `se` whose
/// calibrated uncertainty is the kick's stated SD; its "riding limit" is
/// the warning's threshold, the lower bound less the default
/// `alert.margin_mps`.
#[must_use]
pub fn board_outcomes(recipe: &Recipe, first: u64, campaigns: u64) -> Vec<Outcome> {
    let (factor, floor) = (SIGMA_SE_FACTOR, SIGMA_SD_FLOOR_PER_S);
    (first..first + campaigns)
        .map(|seed| {
            let c = campaign(recipe, seed);
            let mut board = MarginWarning::new(0.0);
            for k in &c.kicks {
                let se = (k.sigma_sd_per_s.powi(2) - floor * floor).max(0.0).sqrt() / factor;
                board.add_kick(&Kick {
                    samples_ago: 0,
                    speed_mps: Some(k.speed_mps as f32),
                    freq_hz: k.freq_hz as f32,
                    sigma_per_s: k.sigma_per_s as f32,
                    sigma_se_per_s: se as f32,
                    amp_deg: 1.0,
                    segments: 10,
                });
            }
            let e = board.estimate();
            score_parts(
                c.wobble_speed_mps,
                e.and_then(|e| e.estimate_mps).map(f64::from),
                [
                    e.map(|e| f64::from(e.lower_mps)),
                    e.and_then(|e| e.upper_mps).map(f64::from),
                ],
                // The warning's threshold: the lower bound less the
                // default `alert.margin_mps`.
                e.map(|e| f64::from(e.lower_mps - DEFAULT_MARGIN_MPS)),
            )
        })
        .collect()
}

/// The figures of a set of outcomes.
#[derive(Clone, Copy, Debug, Default)]
pub struct Tally {
    /// Campaigns.
    pub n: usize,
    /// Closed intervals.
    pub closed: usize,
    /// Closed intervals holding the truth.
    pub covered: usize,
    /// Lower bounds more than 5 % above the truth.
    pub lower_over_5: usize,
    /// ... more than 10 %.
    pub lower_over_10: usize,
    /// Riding limits above the truth.
    pub ride_over: usize,
    /// Point estimates.
    pub estimates: usize,
    /// ... within 5 % of the truth.
    pub within_5: usize,
    /// Closed intervals whose estimate is within 5 %.
    pub closed_within_5: usize,
    /// Median |error| of the point estimates.
    pub median_abs_error: f64,
    /// Median width of the closed intervals over the truth.
    pub median_width: f64,
    /// Wobble speeds claimed where there is none ahead.
    pub false_claims: usize,
}

impl Tally {
    /// Counts `outcomes`.
    #[must_use]
    pub fn of(outcomes: &[Outcome]) -> Self {
        let count = |f: &dyn Fn(&Outcome) -> bool| outcomes.iter().filter(|o| f(o)).count();
        let errors: Vec<f64> = outcomes
            .iter()
            .filter_map(|o| o.error)
            .map(f64::abs)
            .collect();
        Self {
            n: outcomes.len(),
            closed: count(&|o| o.closed),
            covered: count(&|o| o.covered),
            lower_over_5: count(&|o| o.lower_excess.is_some_and(|e| e > 0.05)),
            lower_over_10: count(&|o| o.lower_excess.is_some_and(|e| e > 0.10)),
            ride_over: count(&|o| o.ride_excess.is_some_and(|e| e > 0.0)),
            estimates: outcomes.iter().filter(|o| o.error.is_some()).count(),
            within_5: count(&|o| o.error.is_some_and(|e| e.abs() <= 0.05)),
            closed_within_5: count(&|o| o.closed && o.error.is_some_and(|e| e.abs() <= 0.05)),
            median_abs_error: median(errors),
            median_width: median(outcomes.iter().filter_map(|o| o.width).collect()),
            false_claims: count(&|o| o.false_claim),
        }
    }

    /// Coverage of the closed intervals.
    #[must_use]
    pub fn coverage(&self) -> f64 {
        self.covered as f64 / self.closed.max(1) as f64
    }
}

/// The median of `v` (NaN when empty).
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}
