//! The few transcendental functions the detector needs, without `std` or `libm`.
//!
//! `core` has no `sqrt`/`cos` on stable Rust. The hot path only needs square
//! roots of three Goertzel powers per hop (for the peak interpolation) and of
//! the reported amplitude; cosines are evaluated once, at construction, for the
//! Goertzel coefficients, the window and the high-pass filter. Both are written
//! here so the crate keeps its dependency list to what the card format needs,
//! and both are exact enough that the results match `std` to a few ulp (unit
//! tests compare against `std`).

/// Square root of a non-negative `x`; `0.0` for negative or NaN, `x` for +inf.
///
/// Bit-level initial guess (relative error below 4 %) and three Newton steps:
/// the error squares at each step, 4e-2 -> 8e-4 -> 3e-7 -> below 1 ulp. Cost:
/// 3 divisions, 3 additions, 3 multiplications.
#[must_use]
pub fn sqrtf(x: f32) -> f32 {
    if x.is_nan() || x <= 0.0 {
        return 0.0;
    }
    if x == f32::INFINITY {
        return x;
    }
    let mut y = f32::from_bits(0x1fbd_1df5 + (x.to_bits() >> 1));
    for _ in 0..3 {
        y = 0.5 * (y + x / y);
    }
    y
}

/// Cosine of `x` radians, in `f64` (construction-time only).
///
/// Reduces to `[0, pi/2]` by symmetry, then a Taylor series to x^22, whose
/// truncation error at pi/2 is below 1e-16.
#[must_use]
pub fn cos(x: f64) -> f64 {
    const PI: f64 = core::f64::consts::PI;
    const TAU: f64 = core::f64::consts::TAU;
    if !x.is_finite() {
        return f64::NAN;
    }
    // Reduce to [0, pi]: cos is even and 2*pi periodic. Truncating the
    // quotient instead of `%` keeps `fmod` (3 KiB of soft-float code) out of
    // the firmware; the arguments here are a few turns at most.
    let mut r = x - TAU * ((x / TAU) as i64) as f64;
    if r < 0.0 {
        r = -r;
    }
    if r > PI {
        r = TAU - r;
    }
    // cos(pi - r) = -cos(r): fold to [0, pi/2].
    let (r, sign) = if r > PI / 2.0 {
        (PI - r, -1.0)
    } else {
        (r, 1.0)
    };
    let r2 = r * r;
    let mut term = 1.0;
    let mut sum = 1.0;
    let mut k = 0.0;
    while k < 22.0 {
        term *= -r2 / ((k + 1.0) * (k + 2.0));
        sum += term;
        k += 2.0;
    }
    sign * sum
}

/// Sine of `x` radians, in `f64` (construction-time only).
#[must_use]
pub fn sin(x: f64) -> f64 {
    cos(x - core::f64::consts::FRAC_PI_2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sqrt_matches_std() {
        for &x in &[
            1e-30_f32, 1e-7, 0.01, 0.25, 1.0, 2.0, 3.3, 100.0, 12345.6, 3e30,
        ] {
            let want = x.sqrt();
            let got = sqrtf(x);
            assert!(
                (got - want).abs() <= want * 2.0 * f32::EPSILON,
                "{x}: {got} vs {want}"
            );
        }
        let mut x = 1e-6_f32;
        while x < 1e6 {
            assert!((sqrtf(x) - x.sqrt()).abs() <= x.sqrt() * 2.0 * f32::EPSILON);
            x *= 1.37;
        }
    }

    #[test]
    fn sqrt_edge_cases() {
        assert_eq!(sqrtf(0.0), 0.0);
        assert_eq!(sqrtf(-1.0), 0.0);
        assert_eq!(sqrtf(f32::NAN), 0.0);
        assert_eq!(sqrtf(f32::INFINITY), f32::INFINITY);
    }

    #[test]
    fn cos_sin_match_std() {
        let mut x = -20.0_f64;
        while x < 20.0 {
            assert!((cos(x) - x.cos()).abs() < 1e-13, "cos {x}");
            assert!((sin(x) - x.sin()).abs() < 1e-13, "sin {x}");
            x += 0.0137;
        }
    }
}
