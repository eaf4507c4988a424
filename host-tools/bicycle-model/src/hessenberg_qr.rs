//! Eigenvalues only of a small real matrix: Householder reduction to upper
//! Hessenberg form, then the implicit double-shift (Francis) QR iteration,
//! as LAPACK's `dgeev` does without eigenvectors (`dgehrd`, `dlahqr`).
//!
//! Written here because no crate of the stack has an eigenvalues-only path
//! that is both fast and bounded for a 14 x 14 matrix: nalgebra's
//! `Schur::try_new` (bounded) also accumulates the orthogonal factor and
//! updates the whole Schur form, which is most of its cost in a sweep; its
//! `complex_eigenvalues` skips the factor but iterates without limit and has
//! no exceptional shifts, so a sweep could hang on an unlucky matrix; faer
//! is costly to build (see `docs/model.md`). Here each double-shift step only
//! touches the active block (no Schur form is kept), exceptional shifts break
//! cycles, and the iterations are bounded as in `dlahqr`. The results agree
//! with nalgebra's Schur decomposition to round-off (the tests below).

use nalgebra::{Complex, DMatrix};

/// Iterations allowed per eigenvalue, at least, as in `dlahqr` (30).
const ITERATIONS_PER_ROW: usize = 30;
/// An exceptional shift every this many iterations without deflation.
const EXCEPTIONAL_EVERY: usize = 10;

/// A square matrix, row-major, working storage of the iteration.
struct Square {
    n: usize,
    a: Vec<f64>,
    /// One row's worth of scratch for [`Square::reflect_rows`].
    work: Vec<f64>,
}

impl Square {
    fn at(&self, i: usize, j: usize) -> f64 {
        self.a[i * self.n + j]
    }

    fn set(&mut self, i: usize, j: usize, v: f64) {
        self.a[i * self.n + j] = v;
    }

    /// Applies `I - tau v v^T` (`v[0] = 1`, `v.len()` rows from `r0`) from
    /// the left to columns `cols`, a row at a time through `work`,
    /// contiguous, so that its loops vectorise (the reduction's long
    /// reflectors; the QR steps' short ones go through
    /// [`Square::reflect_short_rows`]).
    fn reflect_rows(&mut self, r0: usize, v: &[f64], tau: f64, cols: std::ops::Range<usize>) {
        let n = self.n;
        let w = &mut self.work[cols.clone()];
        w.fill(0.0);
        for (k, vk) in v.iter().enumerate() {
            let row = &self.a[(r0 + k) * n..][cols.clone()];
            for (x, y) in w.iter_mut().zip(row) {
                *x += vk * y;
            }
        }
        for (k, vk) in v.iter().enumerate() {
            let f = tau * vk;
            let row = &mut self.a[(r0 + k) * n..][cols.clone()];
            for (x, y) in row.iter_mut().zip(w.iter()) {
                *x -= f * y;
            }
        }
    }

    /// [`Square::reflect_rows`] for a reflector of `N` rows (the QR steps'
    /// 3 and 2), in one pass over the columns: the rows are split off once,
    /// each cut to the columns' length, so that the loop has no index
    /// arithmetic and no bounds checks left.
    #[inline(always)]
    fn reflect_short_rows<const N: usize>(
        &mut self,
        r0: usize,
        v: &[f64; N],
        tau: f64,
        cols: std::ops::Range<usize>,
    ) {
        let n = self.n;
        let len = cols.len();
        let mut rest = &mut self.a[r0 * n..];
        let mut rows: [&mut [f64]; N] = std::array::from_fn(|_| {
            let (row, tail) = std::mem::take(&mut rest).split_at_mut(n);
            rest = tail;
            &mut row[cols.clone()][..len]
        });
        if let ([top, middle, bottom], [_, v1, v2]) = (rows.as_mut_slice(), v.as_slice()) {
            return reflect_three_rows(top, middle, bottom, *v1, *v2, tau);
        }
        for j in 0..len {
            let mut s = 0.0;
            for (row, vk) in rows.iter().zip(v) {
                s += vk * row[j];
            }
            s *= tau;
            for (row, vk) in rows.iter_mut().zip(v) {
                row[j] -= s * vk;
            }
        }
    }

    /// Applies `I - tau v v^T` from the right to rows `rows`, columns
    /// `c0..c0 + v.len()`.
    #[inline(always)]
    fn reflect_cols(&mut self, c0: usize, v: &[f64], tau: f64, rows: std::ops::Range<usize>) {
        let n = self.n;
        let cols = c0..c0 + v.len();
        for row in self.a[rows.start * n..rows.end * n].chunks_exact_mut(n) {
            let row = &mut row[cols.clone()];
            let s = tau * row.iter().zip(v).map(|(x, y)| x * y).sum::<f64>();
            for (x, y) in row.iter_mut().zip(v) {
                *x -= s * y;
            }
        }
    }
}

/// `I - tau v v^T`, `v = (1, v1, v2)`, applied to the columns of three rows.
/// Not inlined: as a function's own arguments the rows are known not to
/// overlap, so that the vectorised loop needs no overlap checks.
#[inline(never)]
fn reflect_three_rows(
    top: &mut [f64],
    middle: &mut [f64],
    bottom: &mut [f64],
    v1: f64,
    v2: f64,
    tau: f64,
) {
    for ((x, y), z) in top.iter_mut().zip(middle.iter_mut()).zip(bottom.iter_mut()) {
        let s = tau * (*x + v1 * *y + v2 * *z);
        *x -= s;
        *y -= s * v1;
        *z -= s * v2;
    }
}

/// The Householder reflector `I - tau v v^T` with `v[0] = 1` taking `x` to
/// `(beta, 0, ...)`; `x` is overwritten by `v`. `None` if `x` is already
/// of that form.
#[inline(always)]
fn householder(x: &mut [f64]) -> Option<(f64, f64)> {
    let tail: f64 = x[1..].iter().map(|v| v * v).sum();
    if tail == 0.0 {
        return None;
    }
    let alpha = x[0];
    let beta = -alpha.signum() * (alpha * alpha + tail).sqrt();
    let tau = (beta - alpha) / beta;
    let scale = 1.0 / (alpha - beta);
    x[0] = 1.0;
    for v in &mut x[1..] {
        *v *= scale;
    }
    Some((tau, beta))
}

/// Reduces `h` to upper Hessenberg form by a similarity (Householder).
fn hessenberg(h: &mut Square) {
    let n = h.n;
    let mut v = vec![0.0; n];
    for k in 0..n.saturating_sub(2) {
        let m = n - k - 1;
        for (i, vi) in v[..m].iter_mut().enumerate() {
            *vi = h.at(k + 1 + i, k);
        }
        let Some((tau, beta)) = householder(&mut v[..m]) else {
            continue;
        };
        h.reflect_rows(k + 1, &v[..m], tau, k + 1..n);
        h.reflect_cols(k + 1, &v[..m], tau, 0..n);
        h.set(k + 1, k, beta);
        for i in k + 2..n {
            h.set(i, k, 0.0);
        }
    }
}

/// The eigenvalues of the 2 x 2 block `[[a, b], [c, d]]`.
fn block_2x2(a: f64, b: f64, c: f64, d: f64) -> [Complex<f64>; 2] {
    let p = 0.5 * (a - d);
    let bc = b * c;
    let q = p * p + bc;
    if q >= 0.0 {
        // Real: the root of larger size first, the other from the product.
        let z = p + q.sqrt().copysign(p);
        let first = d + z;
        let second = if z == 0.0 { first } else { d - bc / z };
        [Complex::new(first, 0.0), Complex::new(second, 0.0)]
    } else {
        let im = (-q).sqrt();
        [Complex::new(d + p, im), Complex::new(d + p, -im)]
    }
}

/// The top of the active block ending at row `end`: the row below the last
/// negligible subdiagonal entry (set to zero), or 0.
fn block_start(h: &mut Square, end: usize) -> usize {
    let tiny = f64::EPSILON * f64::EPSILON;
    let mut l = end;
    while l > 0 {
        let off = h.at(l, l - 1).abs();
        if off <= tiny || off <= f64::EPSILON * (h.at(l - 1, l - 1).abs() + h.at(l, l).abs()) {
            h.set(l, l - 1, 0.0);
            break;
        }
        l -= 1;
    }
    l
}

/// One implicit double-shift QR step on the active block `l..=en` with the
/// shifts of the 2 x 2 matrix whose trace is `tr` and determinant `det`.
fn double_shift_step(h: &mut Square, l: usize, en: usize, tr: f64, det: f64) {
    // The first column of (H - s1)(H - s2), from the block's top.
    let (h00, h01, h10, h11) = (
        h.at(l, l),
        h.at(l, l + 1),
        h.at(l + 1, l),
        h.at(l + 1, l + 1),
    );
    let mut v = [
        h00 * h00 + h01 * h10 - tr * h00 + det,
        h10 * (h00 + h11 - tr),
        h10 * h.at(l + 2, l + 1),
    ];
    for k in l..en - 1 {
        if k > l {
            v = [h.at(k, k - 1), h.at(k + 1, k - 1), h.at(k + 2, k - 1)];
        }
        chase(h, l, en, k, &mut v);
    }
    // The last reflector has two rows.
    let mut last = [h.at(en - 1, en - 2), h.at(en, en - 2)];
    chase(h, l, en, en - 1, &mut last);
}

/// Moves the bulge at column `k` of the double-shift step on `l..=en` one
/// row down by the reflector of `v` (the first column of the shift
/// polynomial at `k == l`, else the bulge's column below the diagonal).
#[inline(always)]
fn chase<const N: usize>(h: &mut Square, l: usize, en: usize, k: usize, v: &mut [f64; N]) {
    let Some((tau, beta)) = householder(v) else {
        return;
    };
    if k > l {
        h.set(k, k - 1, beta);
        for i in 1..N {
            h.set(k + i, k - 1, 0.0);
        }
    }
    // Eigenvalues only: nothing outside the active block is needed.
    h.reflect_short_rows(k, v, tau, k..en + 1);
    h.reflect_cols(k, v, tau, l..(k + 4).min(en + 1));
}

/// Approximate eigenvalues offered as shifts, each used at most once: the
/// first step after a deflation shifts by the one nearest the bottom of the
/// active block (with its conjugate, or with the nearest other real one),
/// and each eigenvalue found takes its nearest out. A close guess (the
/// previous speed's eigenvalue, extrapolated) makes that step converge at
/// once, where the block's own shifts need a step or two to get close; any
/// other guess is only a poorer shift, so the result does not depend on it.
struct Guesses(Vec<Complex<f64>>);

impl Guesses {
    /// The index of the guess nearest `z` of those `keep` passes.
    fn nearest(&self, z: Complex<f64>, keep: impl Fn(usize) -> bool) -> Option<usize> {
        let d = |k: usize| (self.0[k] - z).norm_sqr();
        (0..self.0.len())
            .filter(|&k| keep(k))
            .min_by(|&a, &b| d(a).total_cmp(&d(b)))
    }

    /// Takes out the guess of the eigenvalue `z`, found.
    fn found(&mut self, z: Complex<f64>) {
        if let Some(k) = self.nearest(z, |_| true) {
            self.0.swap_remove(k);
        }
    }

    /// The trace and determinant of the shifts for a block whose bottom
    /// diagonal entry is `bottom` (not taken out: their eigenvalues are).
    fn shifts(&self, bottom: f64) -> Option<(f64, f64)> {
        let k = self.nearest(Complex::new(bottom, 0.0), |_| true)?;
        let g = self.0[k];
        if g.im != 0.0 {
            return Some((2.0 * g.re, g.norm_sqr()));
        }
        // A real guess goes with the real guess nearest to it.
        let other = self
            .nearest(g, |j| j != k && self.0[j].im == 0.0)
            .map_or(g.re, |j| self.0[j].re);
        Some((g.re + other, g.re * other))
    }
}

/// The eigenvalues of `a`, in the order they appear on the diagonal of its
/// real Schur form, a pair with the positive imaginary part first; `None`
/// if an entry is not finite or the iteration did not converge within its
/// bound. `guesses`, approximations of them (or none), serve as first shifts
/// ([`Guesses`]): they change the number of steps, not the result.
#[must_use]
pub fn eigenvalues(a: &DMatrix<f64>, guesses: &[Complex<f64>]) -> Option<Vec<Complex<f64>>> {
    let n = a.nrows();
    let rows_of = |h: &mut [f64]| {
        // Row-major from nalgebra's columns.
        for (j, column) in a.as_slice().chunks_exact(n.max(1)).enumerate() {
            for (i, x) in column.iter().enumerate() {
                h[i * n + j] = *x;
            }
        }
    };
    eigenvalues_of(n, rows_of, guesses)
}

/// [`eigenvalues`] of the `n x n` matrix that `fill` writes, row by row,
/// into the slice it is given (the solver's own storage: no matrix is built
/// to be copied).
#[must_use]
pub fn eigenvalues_of(
    n: usize,
    fill: impl FnOnce(&mut [f64]),
    guesses: &[Complex<f64>],
) -> Option<Vec<Complex<f64>>> {
    solve(n, fill, guesses).map(|(values, _)| values)
}

/// [`eigenvalues_of`] and the number of double-shift steps it took.
fn solve(
    n: usize,
    fill: impl FnOnce(&mut [f64]),
    guesses: &[Complex<f64>],
) -> Option<(Vec<Complex<f64>>, usize)> {
    let mut h = Square {
        n,
        a: vec![0.0; n * n],
        work: vec![0.0; n],
    };
    fill(&mut h.a);
    if h.a.iter().any(|v| !v.is_finite()) {
        return None;
    }
    // A power of two near the largest entry: scaling by it is exact.
    let largest = h.a.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let scale = if largest > 0.0 {
        2.0_f64.powi(largest.log2().round() as i32)
    } else {
        1.0
    };
    for x in &mut h.a {
        *x /= scale;
    }
    let mut guesses = Guesses(guesses.iter().map(|g| g / scale).collect());
    hessenberg(&mut h);
    let mut out = vec![Complex::new(0.0, 0.0); n];
    let allowed = ITERATIONS_PER_ROW * n.max(10);
    let mut budget = allowed;
    let mut its = 0;
    let mut end = n;
    while end > 0 {
        let en = end - 1;
        let l = block_start(&mut h, en);
        if l == en {
            out[en] = Complex::new(h.at(en, en), 0.0);
            guesses.found(out[en]);
            end -= 1;
            its = 0;
            continue;
        }
        if l + 1 == en {
            let pair = block_2x2(h.at(l, l), h.at(l, en), h.at(en, l), h.at(en, en));
            out[l] = pair[0];
            out[en] = pair[1];
            guesses.found(pair[0]);
            guesses.found(pair[1]);
            end -= 2;
            its = 0;
            continue;
        }
        if budget == 0 {
            return None;
        }
        budget -= 1;
        its += 1;
        let guessed = if its == 1 {
            guesses.shifts(h.at(en, en))
        } else {
            None
        };
        let (tr, det) = if let Some(shifts) = guessed {
            shifts
        } else if its % EXCEPTIONAL_EVERY == 0 {
            // An ad hoc shift (`dlahqr`'s) breaks a cycle of the standard one.
            let s = h.at(en, en - 1).abs() + h.at(en - 1, en - 2).abs();
            let d = 0.75 * s + h.at(en, en);
            (2.0 * d, d * d + 0.4375 * s * s)
        } else {
            let (p, q, r, t) = (
                h.at(en - 1, en - 1),
                h.at(en - 1, en),
                h.at(en, en - 1),
                h.at(en, en),
            );
            (p + t, p * t - q * r)
        };
        double_shift_step(&mut h, l, en, tr, det);
    }
    for v in &mut out {
        *v *= scale;
    }
    Some((out, allowed - budget))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Schur;
    use proptest::prelude::*;

    /// Each of `got` matched to its own nearest of `want`; the largest
    /// distance relative to `scale`.
    fn worst_distance(got: &[Complex<f64>], want: &[Complex<f64>], scale: f64) -> f64 {
        assert_eq!(got.len(), want.len());
        let mut free: Vec<Complex<f64>> = want.to_vec();
        let mut worst = 0.0_f64;
        for g in got {
            let (k, d) = free
                .iter()
                .map(|w| (w - g).norm())
                .enumerate()
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap();
            free.swap_remove(k);
            worst = worst.max(d / scale);
        }
        worst
    }

    fn reference(a: &DMatrix<f64>) -> Vec<Complex<f64>> {
        Schur::new(a.clone())
            .complex_eigenvalues()
            .iter()
            .copied()
            .collect()
    }

    #[test]
    fn small_matrices_with_known_eigenvalues() {
        // A rotation-and-scale block, a real pair, and a Jordan-free triangle.
        let a = DMatrix::from_row_slice(2, 2, &[1.0, -2.0, 2.0, 1.0]);
        let mut e = eigenvalues(&a, &[]).unwrap();
        e.sort_by(|x, y| x.im.total_cmp(&y.im));
        assert_eq!(e, [Complex::new(1.0, -2.0), Complex::new(1.0, 2.0)]);
        let b = DMatrix::from_row_slice(3, 3, &[2.0, 1.0, 5.0, 0.0, -3.0, 7.0, 0.0, 0.0, 0.5]);
        let mut e: Vec<f64> = eigenvalues(&b, &[]).unwrap().iter().map(|c| c.re).collect();
        e.sort_by(f64::total_cmp);
        assert_eq!(e, [-3.0, 0.5, 2.0]);
        assert_eq!(eigenvalues(&DMatrix::zeros(0, 0), &[]).unwrap(), []);
        assert_eq!(
            eigenvalues(&DMatrix::zeros(4, 4), &[]).unwrap(),
            [Complex::new(0.0, 0.0); 4]
        );
    }

    /// A companion matrix of `(x - 1)(x - 2)...(x - 8)`: real, well apart,
    /// but far from normal.
    #[test]
    fn a_companion_matrix_gives_its_polynomials_roots() {
        let roots: Vec<f64> = (1..=8).map(f64::from).collect();
        let mut coeffs = vec![1.0];
        for r in &roots {
            let mut next = vec![0.0; coeffs.len() + 1];
            for (i, c) in coeffs.iter().enumerate() {
                next[i] += c;
                next[i + 1] -= r * c;
            }
            coeffs = next;
        }
        let n = roots.len();
        let a = DMatrix::from_fn(n, n, |i, j| {
            if i == 0 {
                -coeffs[j + 1]
            } else if i == j + 1 {
                1.0
            } else {
                0.0
            }
        });
        let got = eigenvalues(&a, &[]).unwrap();
        let want: Vec<Complex<f64>> = roots.iter().map(|&r| Complex::new(r, 0.0)).collect();
        assert!(worst_distance(&got, &want, 8.0) < 1e-9);
    }

    /// A permutation matrix: the unit roots, where the standard shifts
    /// stall without the exceptional ones.
    #[test]
    fn a_cyclic_permutation_converges_to_the_unit_roots() {
        let n = 6;
        let a = DMatrix::from_fn(n, n, |i, j| if (j + 1) % n == i { 1.0 } else { 0.0 });
        let got = eigenvalues(&a, &[]).unwrap();
        let want: Vec<Complex<f64>> = (0..n)
            .map(|k| Complex::from_polar(1.0, 2.0 * std::f64::consts::PI * k as f64 / n as f64))
            .collect();
        assert!(worst_distance(&got, &want, 1.0) < 1e-12);
    }

    proptest! {
        /// Random matrices of any size up to 16: the eigenvalues of
        /// nalgebra's Schur decomposition, to round-off of the matrix's size.
        #[test]
        fn random_matrices_match_nalgebra(
            n in 1..=16usize,
            entries in proptest::collection::vec(-1.0e3..1.0e3f64, 256),
            scale_exp in -6..6i32,
        ) {
            let s = 10f64.powi(scale_exp);
            let a = DMatrix::from_fn(n, n, |i, j| s * entries[i * 16 + j]);
            let norm = a.norm();
            let got = eigenvalues(&a, &[]).unwrap();
            let d = worst_distance(&got, &reference(&a), norm);
            prop_assert!(d < 1e-10, "n = {}: {:e}", n, d);
        }

        /// Guesses change the steps, not the result: near ones (the true
        /// eigenvalues moved by up to 1e-3 of the norm), far ones and too
        /// few of them all give nalgebra's eigenvalues.
        #[test]
        fn any_guesses_give_the_same_eigenvalues(
            n in 1..=16usize,
            entries in proptest::collection::vec(-1.0e3..1.0e3f64, 256),
            moves in proptest::collection::vec((-1.0..1.0f64, -1.0..1.0f64), 16),
            kind in 0..3usize,
        ) {
            let a = DMatrix::from_fn(n, n, |i, j| entries[i * 16 + j]);
            let norm = a.norm();
            let want = reference(&a);
            let guesses: Vec<Complex<f64>> = match kind {
                0 => want.iter().zip(&moves).map(|(w, m)| w + Complex::new(m.0, m.1) * 1e-3 * norm).collect(),
                1 => moves.iter().map(|m| Complex::new(m.0, m.1) * norm).collect(),
                _ => want.iter().take(n / 2).copied().collect(),
            };
            let got = eigenvalues(&a, &guesses).unwrap();
            let d = worst_distance(&got, &want, norm);
            prop_assert!(d < 1e-10, "n = {}, guesses of kind {}: {:e}", n, kind, d);
        }

        /// The wobble model's state matrices, with the tense and the passive
        /// rider and the light rider, at any speed: nalgebra's eigenvalues,
        /// each to 1e-10 of its own size (or of 1/s near zero), with no
        /// guesses and with the eigenvalues 0.01 m/s below as guesses (a
        /// sweep's).
        #[test]
        fn model_matrices_match_nalgebra(
            file in proptest::sample::select(vec![
                "paper-test-bicycle.toml",
                "paper-test-bicycle-light-rider.toml",
                "test-bicycle.toml",
            ]),
            u in 0.0..14.0f64,
        ) {
            let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("params").join(file);
            let model = crate::Model::from_set(&crate::ParamSet::load(&path).unwrap()).unwrap();
            let a = model.state_matrix(u);
            let below = eigenvalues(&model.state_matrix(u - 0.01), &[]).unwrap();
            let want = reference(&a);
            let mut got = eigenvalues(&a, &[]).unwrap();
            got.extend(eigenvalues(&a, &below).unwrap());
            for g in &got {
                let d = want.iter().map(|w| (w - g).norm() / w.norm().max(1.0)).fold(f64::INFINITY, f64::min);
                prop_assert!(d < 1e-10, "{} at {} m/s: {} off by {:e}", file, u, g, d);
            }
        }
    }

    /// The model's state matrices at 0-14 m/s, of the three wobble bicycles.
    fn model_matrices() -> Vec<DMatrix<f64>> {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("params");
        let mut out = Vec::new();
        for file in [
            "paper-test-bicycle.toml",
            "paper-test-bicycle-light-rider.toml",
            "test-bicycle.toml",
        ] {
            let set = crate::ParamSet::load(&dir.join(file)).unwrap();
            let model = crate::Model::from_set(&set).unwrap();
            out.extend((0..15).map(|k| model.state_matrix(f64::from(k))));
        }
        out
    }

    fn steps(a: &DMatrix<f64>, guesses: &[Complex<f64>]) -> usize {
        let n = a.nrows();
        let fill = |h: &mut [f64]| {
            for i in 0..n {
                for j in 0..n {
                    h[i * n + j] = a[(i, j)];
                }
            }
        };
        solve(n, fill, guesses).unwrap().1
    }

    /// Francis's double-shift iteration deflates a 1 x 1 or 2 x 2 block in
    /// about two steps (Golub and Van Loan, section 7.5.6), so a 14 x 14
    /// matrix with its 7-14 blocks needs some 14-28 steps (18 on average
    /// here, 26 at most, at standstill); a deflation test that lets
    /// converged entries stand costs a step or more per block beyond that.
    #[test]
    fn model_matrices_deflate_in_about_two_steps_per_block() {
        let matrices = model_matrices();
        let mut total = 0;
        for a in &matrices {
            let n = a.nrows();
            let s = steps(a, &[]);
            assert!(s <= 2 * n, "{s} steps for a {n} x {n} matrix");
            total += s;
        }
        let mean = total as f64 / matrices.len() as f64;
        assert!(mean <= 20.0, "{mean} steps per matrix");
    }

    /// Guesses within 1e-6 of the eigenvalues (a sweep's predictions) take
    /// out steps: the first step after each deflation then brings the next
    /// block close at once (650 steps instead of 803 on these matrices).
    #[test]
    fn close_guesses_save_steps() {
        let (mut plain, mut guessed) = (0, 0);
        for a in model_matrices() {
            let near: Vec<Complex<f64>> = reference(&a)
                .iter()
                .map(|z| z * (1.0 + 1e-6) + Complex::new(1e-6, 0.0))
                .collect();
            plain += steps(&a, &[]);
            guessed += steps(&a, &near);
        }
        assert!(
            100 * guessed <= 85 * plain,
            "{guessed} steps with close guesses, {plain} without"
        );
    }
}
