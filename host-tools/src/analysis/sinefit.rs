//! Least-squares fit of an exponentially growing (or decaying) sinusoid,
//! `e^(sigma tau) (a sin(w tau) + b cos(w tau))` with `tau = t - t0`,
//! directly to the samples: unlike a fit to a smoothed envelope, nothing
//! is blurred, so sigma and the frequency come out unbiased even for fast
//! growth.
//!
//! Optionally a steady tone `c sin(w_h tau) + d cos(w_h tau)` is fitted
//! alongside: a wheel harmonic a fraction of a hertz from the wobble beats
//! with it and would otherwise bend the fitted growth. Or a straight trend
//! `c + d tau` ([`fit_mode_on_trend`]): a slow mode's drift under a slow
//! ring (the weave's, under which the capsize drifts and the band-pass's
//! answer to the kick dies out at a rate like the ring's own).

/// A fitted mode.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SineFit {
    /// Time origin, s.
    pub t0_s: f64,
    /// Growth rate, 1/s.
    pub sigma_per_s: f64,
    /// Angular frequency, rad/s.
    pub omega_rad_s: f64,
    /// ln of the amplitude at `t0_s`.
    pub log_amp: f64,
    /// RMS of what the model leaves unexplained over RMS of the samples: 0
    /// for a perfect fit, near 1 when there is no such mode.
    pub residual_rel: f64,
    /// Standard error of `sigma_per_s`, 1/s: `s^2 (J^T J)^-1` at the
    /// optimum (`s^2` the residual variance), times the residuals' spectral
    /// density at the mode's frequency over their mean density (see
    /// [`colour_factor`]): what a filtered signal or a mode kept ringing by
    /// the road leaves near the mode weighs on sigma more than white noise
    /// of the same variance.
    pub sigma_se_per_s: f64,
}

const ITERATIONS: usize = 60;
/// A step that lowers the cost by less than this many residual variances
/// ends the search: the parameters then move by well under a hundredth of
/// their standard error (a cost change of `s^2 k^2` moves them about `k`
/// standard errors).
const CONVERGED: f64 = 1e-4;
/// Parameters: a, b, sigma, w, then c, d, w_h with a tone, or c, d with a
/// trend.
const MAX_PARAMS: usize = 7;
/// Parameters with a trend.
const TREND_PARAMS: usize = 6;

type Vector = [f64; MAX_PARAMS];
type Matrix = [[f64; MAX_PARAMS]; MAX_PARAMS];

/// Fits `x` sampled at `t` by Levenberg-Marquardt, starting from `sigma0`
/// and `omega0`, with a steady tone starting at `tone_omega0` if given.
/// `None` if there are too few samples or no finite mode is found.
#[must_use]
pub fn fit_mode(
    t: &[f64],
    x: &[f64],
    sigma0: f64,
    omega0: f64,
    tone_omega0: Option<f64>,
) -> Option<SineFit> {
    let beside = tone_omega0.map_or(Beside::Nothing, Beside::Tone);
    fit_mode_until(t, x, sigma0, omega0, beside, CONVERGED)
}

/// [`fit_mode`] with a straight trend `c + d tau` fitted beside the mode
/// instead of a tone.
#[must_use]
pub fn fit_mode_on_trend(t: &[f64], x: &[f64], sigma0: f64, omega0: f64) -> Option<SineFit> {
    fit_mode_until(t, x, sigma0, omega0, Beside::Trend, CONVERGED)
}

/// What is fitted beside the mode.
#[derive(Clone, Copy)]
enum Beside {
    Nothing,
    /// A steady tone starting at this angular frequency, rad/s.
    Tone(f64),
    Trend,
}

/// [`fit_mode`], ending the search where a step lowers the cost by less
/// than `converged` residual variances.
fn fit_mode_until(
    t: &[f64],
    x: &[f64],
    sigma0: f64,
    omega0: f64,
    beside: Beside,
    converged: f64,
) -> Option<SineFit> {
    let t0_s = *t.first()?;
    if t.len() < 8 {
        return None;
    }
    let (a, b) = linear_part(t, x, t0_s, sigma0, omega0)?;
    let (n, tone_omega0) = match beside {
        Beside::Nothing => (4, 0.0),
        Beside::Tone(w) => (MAX_PARAMS, w),
        Beside::Trend => (TREND_PARAMS, 0.0),
    };
    let grid = Grid::of(t);
    let mut p: Vector = [a, b, sigma0, omega0, 0.0, 0.0, tone_omega0];
    // Each trial's normal equations come with its cost (one pass over the
    // samples): an accepted trial's are the next iteration's.
    let mut at_p = normal_equations(&grid, t, x, &p, n);
    let mut lambda = 1e-3;
    for _ in 0..ITERATIONS {
        let (jtj, jtr, cost) = at_p;
        let mut damped = jtj;
        for (k, row) in damped.iter_mut().enumerate().take(n) {
            row[k] += lambda * jtj[k][k].max(1e-12);
        }
        let Some(step) = solve(damped, jtr, n) else {
            break;
        };
        let mut trial = p;
        trial.iter_mut().zip(step).for_each(|(v, s)| *v += s);
        let at_trial = normal_equations(&grid, t, x, &trial, n);
        let trial_cost = at_trial.2;
        if trial_cost.is_finite() && trial_cost < cost {
            let converged = (cost - trial_cost) <= converged * cost / (t.len() - n).max(1) as f64;
            p = trial;
            at_p = at_trial;
            lambda = (lambda * 0.3).max(1e-9);
            if converged {
                break;
            }
        } else {
            lambda *= 10.0;
        }
    }
    let (_, _, cost) = at_p;
    let amp = p[0].hypot(p[1]);
    let power: f64 = x.iter().map(|v| v * v).sum();
    let finite = p.iter().all(|v| v.is_finite());
    (amp > 0.0 && power > 0.0 && finite && p[3] > 0.0).then(|| SineFit {
        t0_s,
        sigma_per_s: p[2],
        omega_rad_s: p[3],
        log_amp: amp.ln(),
        residual_rel: (cost / power).sqrt(),
        sigma_se_per_s: standard_error(&grid, t, x, &p, n, cost, 2)
            * colour_factor(t, x, t0_s, &p, n).sqrt(),
    })
}

/// The residuals' spectral density at the mode's frequency over their mean
/// density (1 for white residuals), from their autocorrelation `rho_k`:
/// `1 + 2 sum_k (1 - k/K) rho_k cos(omega k dt)` up to a quarter of the
/// samples (a Bartlett-tapered estimate), never below 1.
fn colour_factor(t: &[f64], x: &[f64], t0: f64, p: &Vector, n: usize) -> f64 {
    let r: Vec<f64> = t
        .iter()
        .zip(x)
        .map(|(&ts, &xv)| xv - model(ts - t0, p, n).0)
        .collect();
    let len = r.len();
    let var = r.iter().map(|v| v * v).sum::<f64>() / len as f64;
    if len < 8 || var.is_nan() || var <= 0.0 {
        return 1.0;
    }
    let dt = (t[len - 1] - t[0]) / (len - 1) as f64;
    let lags = len / 4;
    let mut factor = 1.0;
    for k in 1..lags {
        let rho = r.iter().zip(&r[k..]).map(|(a, b)| a * b).sum::<f64>() / (len as f64 * var);
        let taper = 1.0 - k as f64 / lags as f64;
        factor += 2.0 * taper * rho * (p[3] * k as f64 * dt).cos();
    }
    factor.max(1.0)
}

/// Standard error of parameter `k` at `p`: `sqrt(s^2 [(J^T J)^-1]_kk)` with
/// `s^2 = cost / (samples - parameters)`; infinite where `J^T J` is
/// singular.
fn standard_error(
    grid: &Grid,
    t: &[f64],
    x: &[f64],
    p: &Vector,
    n: usize,
    cost: f64,
    k: usize,
) -> f64 {
    let (jtj, _, _) = normal_equations(grid, t, x, p, n);
    let mut unit = [0.0; MAX_PARAMS];
    unit[k] = 1.0;
    let dof = t.len().saturating_sub(n).max(1) as f64;
    solve(jtj, unit, n).map_or(f64::INFINITY, |col| (cost / dof * col[k].max(0.0)).sqrt())
}

/// The model's oscillating parts at `tau`: `e^(sigma tau)`, the mode's
/// sine and cosine, the tone's sine and cosine.
#[derive(Clone, Copy)]
struct Phasors {
    e: f64,
    s: f64,
    c: f64,
    sh: f64,
    ch: f64,
}

impl Phasors {
    fn at(tau: f64, p: &Vector) -> Self {
        let (s, c) = (p[3] * tau).sin_cos();
        let (sh, ch) = (p[6] * tau).sin_cos();
        Self {
            e: (p[2] * tau).exp(),
            s,
            c,
            sh,
            ch,
        }
    }

    /// These advanced by `by` (the angle-sum formulas).
    fn advanced(self, by: &Self) -> Self {
        Self {
            e: self.e * by.e,
            s: self.s * by.c + self.c * by.s,
            c: self.c * by.c - self.s * by.s,
            sh: self.sh * by.ch + self.ch * by.sh,
            ch: self.ch * by.ch - self.sh * by.sh,
        }
    }
}

/// Samples between exact evaluations on an even grid: the recurrence's
/// round-off (a few ulps per step) stays below 1e-13 of the model.
const EXACT_EVERY: usize = 64;

/// The samples' times from the first: on an even grid (the episode and
/// kick spans are resampled to one), the phasors advance by recurrence,
/// a multiplication per sample instead of three transcendental functions,
/// which were most of a fit's time; otherwise each is evaluated.
pub(super) struct Grid {
    t0: f64,
    step: Option<f64>,
}

impl Grid {
    /// How far a time may lie from the even grid through the first and last
    /// samples, s: a phase error of 1e-8 rad at 10 Hz.
    const TOLERANCE_S: f64 = 1e-10;

    pub(super) fn of(t: &[f64]) -> Self {
        let t0 = t.first().copied().unwrap_or(0.0);
        let step = match t {
            [first, .., last] => {
                let step = (last - first) / (t.len() - 1) as f64;
                let even = t
                    .iter()
                    .enumerate()
                    .all(|(i, ts)| (ts - first - i as f64 * step).abs() <= Self::TOLERANCE_S);
                (step > 0.0 && even).then_some(step)
            }
            _ => None,
        };
        Self { t0, step }
    }

    /// Calls `each(i, sin, cos)` of `omega tau_i` for every sample.
    pub(super) fn for_each_sin_cos(
        &self,
        t: &[f64],
        omega: f64,
        mut each: impl FnMut(usize, f64, f64),
    ) {
        let mut p = [0.0; MAX_PARAMS];
        p[3] = omega;
        self.for_each(t, &p, |i, _, ph| each(i, ph.s, ph.c));
    }

    /// Calls `each(i, tau_i, phasors_i)` for every sample.
    fn for_each(&self, t: &[f64], p: &Vector, mut each: impl FnMut(usize, f64, &Phasors)) {
        let Some(step) = self.step else {
            for (i, ts) in t.iter().enumerate() {
                let tau = ts - self.t0;
                each(i, tau, &Phasors::at(tau, p));
            }
            return;
        };
        let by = Phasors::at(step, p);
        let mut ph = Phasors::at(0.0, p);
        for i in 0..t.len() {
            let tau = i as f64 * step;
            if i % EXACT_EVERY == 0 {
                ph = Phasors::at(tau, p);
            }
            each(i, tau, &ph);
            ph = ph.advanced(&by);
        }
    }
}

/// The model from its phasors at `tau`, and its derivatives by each
/// parameter.
fn model_of(tau: f64, ph: &Phasors, p: &Vector, n: usize) -> (f64, Vector) {
    let Phasors { e, s, c, sh, ch } = *ph;
    let mode = e * (p[0] * s + p[1] * c);
    let mut j = [0.0; MAX_PARAMS];
    j[..4].copy_from_slice(&[e * s, e * c, tau * mode, tau * e * (p[0] * c - p[1] * s)]);
    if n == TREND_PARAMS {
        j[4..TREND_PARAMS].copy_from_slice(&[1.0, tau]);
        return (mode + p[4] + p[5] * tau, j);
    }
    if n < MAX_PARAMS {
        return (mode, j);
    }
    j[4..].copy_from_slice(&[sh, ch, tau * (p[4] * ch - p[5] * sh)]);
    (mode + p[4] * sh + p[5] * ch, j)
}

/// The model at `tau` and its derivatives by each parameter.
fn model(tau: f64, p: &Vector, n: usize) -> (f64, Vector) {
    model_of(tau, &Phasors::at(tau, p), p, n)
}

/// `a` and `b` for fixed `sigma` and `omega` (linear least squares).
fn linear_part(t: &[f64], x: &[f64], t0: f64, sigma: f64, omega: f64) -> Option<(f64, f64)> {
    let (mut ss, mut sc, mut cc, mut xs, mut xc) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (&ts, &xv) in t.iter().zip(x) {
        let tau = ts - t0;
        let e = (sigma * tau).exp();
        let (s, c) = (omega * tau).sin_cos();
        let (s, c) = (e * s, e * c);
        ss += s * s;
        sc += s * c;
        cc += c * c;
        xs += xv * s;
        xc += xv * c;
    }
    let det = ss * cc - sc * sc;
    (det.abs() > 1e-12).then(|| ((xs * cc - xc * sc) / det, (xc * ss - xs * sc) / det))
}

/// `J^T J`, `J^T r` and the cost (the sum of squared residuals) at `p`.
fn normal_equations(
    grid: &Grid,
    t: &[f64],
    x: &[f64],
    p: &Vector,
    n: usize,
) -> (Matrix, Vector, f64) {
    // The count as a constant lets the compiler unroll the per-sample
    // products: most of a fit's time is here.
    match n {
        MAX_PARAMS => normal_equations_of::<MAX_PARAMS>(grid, t, x, p),
        TREND_PARAMS => normal_equations_of::<TREND_PARAMS>(grid, t, x, p),
        _ => normal_equations_of::<4>(grid, t, x, p),
    }
}

/// [`normal_equations`] with `N` parameters.
fn normal_equations_of<const N: usize>(
    grid: &Grid,
    t: &[f64],
    x: &[f64],
    p: &Vector,
) -> (Matrix, Vector, f64) {
    let mut jtj = [[0.0; MAX_PARAMS]; MAX_PARAMS];
    let mut jtr = [0.0; MAX_PARAMS];
    let mut cost = 0.0;
    grid.for_each(t, p, |i, tau, ph| {
        let (m, j) = model_of(tau, ph, p, N);
        let r = x[i] - m;
        cost += r * r;
        for row in 0..N {
            jtr[row] += j[row] * r;
            // The upper triangle; the lower is its mirror.
            for col in row..N {
                jtj[row][col] += j[row] * j[col];
            }
        }
    });
    for row in 1..N {
        let (upper, lower) = jtj.split_at_mut(row);
        for (col, above) in upper.iter().enumerate() {
            lower[0][col] = above[row];
        }
    }
    (jtj, jtr, cost)
}

/// Solves the leading `n`x`n` system by Gaussian elimination with partial
/// pivoting.
fn solve(mut m: Matrix, mut v: Vector, n: usize) -> Option<Vector> {
    for col in 0..n {
        let pivot = (col..n).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))?;
        if m[pivot][col].abs() < 1e-300 {
            return None;
        }
        m.swap(col, pivot);
        v.swap(col, pivot);
        let pivot_row = m[col];
        for row in col + 1..n {
            let f = m[row][col] / pivot_row[col];
            for (a, b) in m[row][col..n].iter_mut().zip(&pivot_row[col..n]) {
                *a -= f * b;
            }
            v[row] -= f * v[col];
        }
    }
    let mut out = [0.0; MAX_PARAMS];
    for row in (0..n).rev() {
        let tail: f64 = (row + 1..n).map(|k| m[row][k] * out[k]).sum();
        out[row] = (v[row] - tail) / m[row][row];
    }
    out.iter().all(|v| v.is_finite()).then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::f64::consts::TAU;

    fn signal(t: &[f64], sigma: f64, f_hz: f64, amp: f64, phase: f64) -> Vec<f64> {
        t.iter()
            .map(|ts| amp * (sigma * (ts - t[0])).exp() * (TAU * f_hz * (ts - t[0]) + phase).sin())
            .collect()
    }

    /// Gaussian noise from a xorshift generator (Box-Muller).
    fn noise(state: &mut u64) -> f64 {
        let mut uniform = || {
            *state ^= *state << 13;
            *state ^= *state >> 7;
            *state ^= *state << 17;
            (*state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (u1, u2) = (uniform().max(1e-300), uniform());
        (-2.0 * u1.ln()).sqrt() * (TAU * u2).cos()
    }

    /// The standard error is `sqrt(cost / (N - n) [(J^T J)^-1]_kk)`: here
    /// with the Jacobian by central differences of the model written out
    /// again and inverted by nalgebra, apart from the code's analytic one
    /// and its elimination. 24 samples, 4 parameters: 20 degrees of freedom.
    #[test]
    fn the_standard_error_has_samples_less_parameters_degrees_of_freedom() {
        let t: Vec<f64> = (0..24).map(|i| f64::from(i) * 0.01).collect();
        let x: Vec<f64> = t.iter().map(|&ts| (TAU * 7.0 * ts).sin()).collect();
        let mut p = [0.0; MAX_PARAMS];
        p[..4].copy_from_slice(&[1.1, 0.2, -1.3, TAU * 6.8]);
        let f = |q: &[f64; 4], tau: f64| {
            (q[2] * tau).exp() * (q[0] * (q[3] * tau).sin() + q[1] * (q[3] * tau).cos())
        };
        let q = [p[0], p[1], p[2], p[3]];
        let mut jtj = nalgebra::Matrix4::<f64>::zeros();
        for &tau in &t {
            let mut row = [0.0; 4];
            for (k, d) in row.iter_mut().enumerate() {
                let (mut up, mut down) = (q, q);
                up[k] += 1e-6;
                down[k] -= 1e-6;
                *d = (f(&up, tau) - f(&down, tau)) / 2e-6;
            }
            let j = nalgebra::Vector4::from(row);
            jtj += j * j.transpose();
        }
        let inverse = jtj.try_inverse().unwrap();
        let cost = 0.37;
        for k in 0..4 {
            let want = (cost / 20.0 * inverse[(k, k)]).sqrt();
            let got = standard_error(&Grid::of(&t), &t, &x, &p, 4, cost, k);
            assert!(
                (got - want).abs() < 1e-5 * want,
                "{k}: {got} against {want}"
            );
        }
    }

    /// On an even grid the phasors by recurrence are the functions evaluated
    /// at each sample (2000 samples, far from time zero: within 1e-10, the
    /// samples' own times rounded to some 1e-13 s); a
    /// grid with one sample a microsecond off is evaluated sample by sample.
    #[test]
    fn the_recurrence_is_the_functions_on_an_even_grid() {
        let t: Vec<f64> = (0..2000).map(|i| 1234.5 + f64::from(i) / 100.0).collect();
        let p = [0.0, 0.0, -0.3, TAU * 6.3, 0.0, 0.0, TAU * 5.9];
        let grid = Grid::of(&t);
        assert!(grid.step.is_some());
        let mut seen = 0;
        let mut worst = 0.0f64;
        grid.for_each(&t, &p, |i, tau, ph| {
            let want = Phasors::at(t[i] - t[0], &p);
            worst = worst
                .max((tau - (t[i] - t[0])).abs())
                .max((ph.e / want.e - 1.0).abs())
                .max((ph.s - want.s).abs())
                .max((ph.c - want.c).abs())
                .max((ph.sh - want.sh).abs())
                .max((ph.ch - want.ch).abs());
            seen += 1;
        });
        assert_eq!(seen, t.len());
        assert!(worst < 1e-10, "{worst}");
        let mut jittered = t.clone();
        jittered[1000] += 1e-6;
        assert!(Grid::of(&jittered).step.is_none());
        assert!(Grid::of(&t[..1]).step.is_none());
    }

    /// Residuals that alternate in sign are anti-correlated: the sum of
    /// their autocorrelations is below 1, and so would the factor be; it
    /// never narrows an interval below the white-noise one.
    #[test]
    fn the_colour_factor_is_never_below_one() {
        let t: Vec<f64> = (0..64).map(|i| f64::from(i) * 0.01).collect();
        let x: Vec<f64> = (0..64)
            .map(|i| if i % 2 == 0 { 0.1 } else { -0.1 })
            .collect();
        // No mode (a = b = 0) and omega 0: the residuals are `x`, every
        // lag's cosine 1.
        let p = [0.0; MAX_PARAMS];
        assert_eq!(colour_factor(&t, &x, 0.0, &p, 4), 1.0);
    }

    /// The standard error of sigma is the spread of sigma over repeated
    /// noisy realisations of the same ring-down (Monte Carlo, 200 draws):
    /// within 20 % of it.
    #[test]
    fn sigma_standard_error_is_the_scatter_over_noise() {
        let t: Vec<f64> = (0..150).map(|i| f64::from(i) / 100.0).collect();
        let clean = signal(&t, -1.5, 7.0, 1.0, 0.3);
        let mut state = 0x2545_F491_4F6C_DD1D_u64;
        let (mut sigmas, mut ses) = (Vec::new(), Vec::new());
        for _ in 0..200 {
            let x: Vec<f64> = clean.iter().map(|v| v + 0.05 * noise(&mut state)).collect();
            let fit = fit_mode(&t, &x, -1.0, TAU * 7.1, None).unwrap();
            sigmas.push(fit.sigma_per_s);
            ses.push(fit.sigma_se_per_s);
        }
        let n = sigmas.len() as f64;
        let mean = sigmas.iter().sum::<f64>() / n;
        let spread = (sigmas.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let se = ses.iter().sum::<f64>() / n;
        assert!((se / spread - 1.0).abs() < 0.2, "se {se} spread {spread}");
        assert!(
            (mean + 1.5).abs() < 3.0 * spread / n.sqrt(),
            "unbiased: {mean}"
        );
    }

    proptest! {
        // Each case fits a few hundred samples some dozens of times.
        #![proptest_config(ProptestConfig::with_cases(48))]

        /// From a start 0.15 Hz and 30 % off, the fit finds the mode of a
        /// clean damped or growing sinusoid.
        #[test]
        fn recovers_a_mode(
            sigma in prop_oneof![-6.0..-0.5f64, 0.5..4.0f64],
            f_hz in 5.5..9.5f64,
            amp in 0.1..5.0f64,
            phase in 0.0..TAU,
        ) {
            let t: Vec<f64> = (0..120).map(|i| 10.0 + f64::from(i) / 100.0).collect();
            let x = signal(&t, sigma, f_hz, amp, phase);
            let fit = fit_mode(&t, &x, sigma * 0.7, TAU * (f_hz + 0.15), None).unwrap();
            prop_assert!((fit.sigma_per_s - sigma).abs() < 1e-3 * sigma.abs().max(1.0));
            prop_assert!((fit.omega_rad_s - TAU * f_hz).abs() < 1e-3);
            prop_assert!((fit.log_amp - amp.ln()).abs() < 1e-3);
            prop_assert!(fit.residual_rel < 1e-3);
        }

        /// The search ends where the parameters have all but stopped: on a
        /// noisy decaying ring beside a tone, sigma ends within a fiftieth
        /// of its standard error of where a search run to a cost change of
        /// 1e-12 residual variances ends.
        #[test]
        fn the_search_ends_at_the_optimum(
            sigma in -5.0..-0.5f64,
            f_hz in 6.0..8.5f64,
            noise_deg in 0.01..0.2f64,
            seed in 1..u64::MAX,
        ) {
            let t: Vec<f64> = (0..400).map(|i| f64::from(i) / 100.0).collect();
            let ring = signal(&t, sigma, f_hz, 1.0, 0.4);
            let tone = signal(&t, 0.0, f_hz + 0.4, 0.1, 1.1);
            let mut state = seed;
            let x: Vec<f64> = ring
                .iter()
                .zip(&tone)
                .map(|(a, b)| a + b + noise_deg * noise(&mut state))
                .collect();
            let guess = (0.7 * sigma, TAU * (f_hz + 0.1), Some(TAU * (f_hz + 0.45)));
            let beside = guess.2.map_or(Beside::Nothing, Beside::Tone);
            let at = |converged| fit_mode_until(&t, &x, guess.0, guess.1, beside, converged);
            let (fit, tight) = (at(CONVERGED).unwrap(), at(1e-12).unwrap());
            prop_assert!(
                (fit.sigma_per_s - tight.sigma_per_s).abs() <= 0.02 * tight.sigma_se_per_s,
                "{fit:?} against {tight:?}"
            );
        }

        /// A steady tone 0.1-0.6 Hz from a growing mode, as large as the
        /// mode's start, is separated from it.
        #[test]
        fn separates_a_steady_tone(
            sigma in 0.8..3.0f64,
            f_hz in 6.0..8.5f64,
            offset_hz in prop_oneof![-0.6..-0.1f64, 0.1..0.6f64],
            tone_deg in 0.05..0.2f64,
        ) {
            let t: Vec<f64> = (0..600).map(|i| f64::from(i) / 100.0).collect();
            let growth = signal(&t, sigma, f_hz, 0.05, 0.4);
            let tone = signal(&t, 0.0, f_hz + offset_hz, tone_deg, 1.1);
            let x: Vec<f64> = growth.iter().zip(&tone).map(|(a, b)| a + b).collect();
            let guess = TAU * (f_hz + offset_hz + 0.05);
            let fit = fit_mode(&t, &x, sigma, TAU * f_hz, Some(guess)).unwrap();
            prop_assert!((fit.sigma_per_s - sigma).abs() < 0.02 * sigma, "{fit:?}");
            prop_assert!((fit.log_amp - 0.05f64.ln()).abs() < 0.05, "{fit:?}");
        }
    }
}
