//! `encode --resample`: rows of a CSV at any rate (or an uneven one) onto the
//! log's frame grid, by linear interpolation of the stored counts between
//! neighbouring rows. Rows further apart than [`MAX_STEP_US`] are a gap: no
//! frame is made between them, as in a log with frames missing, and the grid
//! starts again at the row after it. The GPS fix and UTC of a frame are the
//! row's before it (a fix is an event, not a signal to interpolate); UTC
//! advances with the frame's time from there.
//!
//! There is no anti-alias filter: a CSV sampled faster than the log is
//! point-sampled, so what it holds above half the log's rate (50 Hz) folds
//! down. The wobble band (6-9 Hz) and everything the analyses use lie far
//! below that.

use wobble_core::format::{Frame, GpsFix};

/// Rows further apart than this are a gap, µs: ten frames at 100 Hz.
pub const MAX_STEP_US: u64 = 100_000;

/// One CSV row as the log stores it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CsvRow {
    /// The frame: counts and time.
    pub frame: Frame,
    /// The GPS fix the row gives.
    pub gps: Option<GpsFix>,
    /// UTC, µs since 1970.
    pub utc_us: Option<i64>,
}

/// Resamples rows (time strictly increasing) onto a grid `period_us` apart.
pub struct Resampler {
    period_us: u64,
    /// The row before, and the next grid time.
    prev: Option<(CsvRow, u64)>,
}

impl Resampler {
    /// A resampler onto frames `period_us` apart (at least 1).
    #[must_use]
    pub fn new(period_us: u64) -> Self {
        Self {
            period_us: period_us.max(1),
            prev: None,
        }
    }

    /// Takes the next row; calls `emit` for every frame of the grid before
    /// it, in time order.
    ///
    /// # Errors
    /// The first error `emit` returns.
    pub fn push<E>(
        &mut self,
        row: CsvRow,
        emit: &mut impl FnMut(&CsvRow) -> Result<(), E>,
    ) -> Result<(), E> {
        let t = row.frame.t_us;
        let next = match self.prev {
            Some((a, next)) if t.saturating_sub(a.frame.t_us) <= MAX_STEP_US => {
                let mut next = next;
                while next < t {
                    emit(&between(&a, &row, next))?;
                    next += self.period_us;
                }
                next
            }
            _ => {
                self.finish(emit)?;
                t
            }
        };
        self.prev = Some((row, next));
        Ok(())
    }

    /// Ends the rows: the last one is a frame if it lies on the grid.
    ///
    /// # Errors
    /// The error `emit` returns.
    pub fn finish<E>(&mut self, emit: &mut impl FnMut(&CsvRow) -> Result<(), E>) -> Result<(), E> {
        match self.prev.take() {
            Some((a, next)) if next == a.frame.t_us => emit(&a),
            _ => Ok(()),
        }
    }
}

/// The frame at `t_us` between rows `a` and `b` (`a` at or before it, `b`
/// after it): counts interpolated, GPS and UTC from `a`.
fn between(a: &CsvRow, b: &CsvRow, t_us: u64) -> CsvRow {
    let (fa, fb) = (&a.frame, &b.frame);
    let w = (t_us - fa.t_us) as f64 / (fb.t_us - fa.t_us) as f64;
    let lerp = |x: f64, y: f64| x + w * (y - x);
    // Between two stored counts, so the rounded value is one too.
    let i16_at = |x: i16, y: i16| lerp(f64::from(x), f64::from(y)).round() as i16;
    let since_us = t_us - fa.t_us;
    CsvRow {
        frame: Frame {
            t_us,
            accel: std::array::from_fn(|k| i16_at(fa.accel[k], fb.accel[k])),
            gyro: std::array::from_fn(|k| i16_at(fa.gyro[k], fb.gyro[k])),
            steer_cdeg: i16_at(fa.steer_cdeg, fb.steer_cdeg),
            speed_mm_s: lerp(f64::from(fa.speed_mm_s), f64::from(fb.speed_mm_s)).round() as u16,
            ..*fa
        },
        gps: a.gps,
        utc_us: a.utc_us.map(|us| us + since_us as i64),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A row at `t_us` whose every channel is a multiple of `v` (wrapping:
    /// the property below takes any `v`).
    fn row(t_us: u64, v: i16) -> CsvRow {
        CsvRow {
            frame: Frame {
                t_us,
                accel: [v, v.wrapping_neg(), v.wrapping_mul(2)],
                gyro: [v.wrapping_neg(), v, v.wrapping_mul(3)],
                steer_cdeg: v,
                speed_mm_s: v.unsigned_abs().wrapping_mul(4),
                ..Frame::default()
            },
            gps: Some(GpsFix {
                t_us,
                lat_e7: Some(i32::from(v)),
                ..GpsFix::default()
            }),
            utc_us: Some(1_600_000_000_000_000 + t_us as i64),
        }
    }

    fn resample(rows: &[CsvRow], period_us: u64) -> Vec<CsvRow> {
        let mut out = Vec::new();
        let mut r = Resampler::new(period_us);
        let mut keep = |f: &CsvRow| -> Result<(), ()> {
            out.push(*f);
            Ok(())
        };
        for &row in rows {
            r.push(row, &mut keep).unwrap();
        }
        r.finish(&mut keep).unwrap();
        out
    }

    #[test]
    fn a_line_is_sampled_on_the_grid() {
        // 40 Hz rows of a ramp of 1 count per ms, onto 100 Hz.
        let rows: Vec<CsvRow> = (0..5).map(|i| row(25_000 * i, 25 * i as i16)).collect();
        let out = resample(&rows, 10_000);
        let times: Vec<u64> = out.iter().map(|f| f.frame.t_us).collect();
        assert_eq!(times, (0..=10).map(|k| 10_000 * k).collect::<Vec<_>>());
        for f in &out {
            let ms = (f.frame.t_us / 1000) as i16;
            assert_eq!(f.frame, row(f.frame.t_us, ms).frame);
            assert_eq!(f.utc_us, Some(1_600_000_000_000_000 + f.frame.t_us as i64));
            // The fix of the row at or before the frame, never made up.
            assert_eq!(f.gps, rows[(f.frame.t_us / 25_000) as usize].gps);
        }
    }

    #[test]
    fn no_frame_is_made_across_a_gap() {
        let rows = [row(0, 0), row(5_000, 5), row(500_000, 50), row(505_000, 55)];
        // The grid starts again at the row after the gap; each frame is the
        // row at its time.
        assert_eq!(resample(&rows, 10_000), vec![rows[0], rows[2]]);
        // A stretch's last row is a frame when it lies on the grid, with its
        // own fix.
        let rows = [row(0, 0), row(5_000, 5), row(10_000, 10), row(500_000, 50)];
        assert_eq!(resample(&rows, 10_000), vec![rows[0], rows[2], rows[3]]);
    }

    proptest! {
        /// Any increasing rows give frames on the grid of their stretch,
        /// each between its neighbouring rows' values, none in a gap.
        #[test]
        fn frames_lie_between_their_rows(
            steps in proptest::collection::vec((1u64..150_000, any::<i16>()), 1..200),
        ) {
            let mut t = 0;
            let rows: Vec<CsvRow> = steps.iter().map(|&(dt, v)| { t += dt; row(t, v) }).collect();
            let out = resample(&rows, 10_000);
            prop_assert!(out.windows(2).all(|w| w[0].frame.t_us < w[1].frame.t_us));
            for f in &out {
                let t = f.frame.t_us;
                let after = rows.partition_point(|r| r.frame.t_us <= t);
                let a = &rows[after - 1];
                if a.frame.t_us == t {
                    prop_assert_eq!(f.frame.steer_cdeg, a.frame.steer_cdeg);
                    continue;
                }
                let b = &rows[after];
                prop_assert!(b.frame.t_us - a.frame.t_us <= MAX_STEP_US);
                let (lo, hi) = if a.frame.steer_cdeg <= b.frame.steer_cdeg {
                    (a.frame.steer_cdeg, b.frame.steer_cdeg)
                } else {
                    (b.frame.steer_cdeg, a.frame.steer_cdeg)
                };
                prop_assert!((lo..=hi).contains(&f.frame.steer_cdeg));
            }
        }
    }
}
