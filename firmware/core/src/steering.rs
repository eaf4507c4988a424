//! Steering angle: potentiometer ADC counts -> degrees, one value per frame.
//!
//! The ADC samples the potentiometer much faster than 100 Hz; every sample is
//! added to a [`Boxcar`] and each frame takes the mean of the samples since
//! the previous frame (the anti-alias filter, see [`crate::decimate`]). The
//! mean in counts is then calibrated to degrees, positive to the left:
//!
//! - two-point (default): `deg = (counts − center_counts) × deg_per_count`;
//! - three-point: piecewise linear through three measured (counts, degrees)
//!   points, e.g. full left, straight ahead, full right, which absorbs a
//!   potentiometer or linkage that is not linear across the range.
//!
//! A frame's value is saturated when any of its samples came within the margin
//! of either end of the ADC range: the potentiometer is at an end stop, its
//! wiper lifted, or it is unplugged, and the mean is not the angle.

use core::fmt;

use crate::decimate::Boxcar;

/// One calibration point.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CalPoint {
    /// ADC counts measured at this angle.
    pub counts: f32,
    /// The angle, degrees, positive to the left.
    pub deg: f32,
}

/// Steering calibration and ADC limits.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SteeringCalibration {
    /// ADC counts with the handlebar straight ahead. Default 2048: mid-range.
    pub center_counts: f32,
    /// Degrees per ADC count, positive to the left; negative if the
    /// potentiometer turns the other way. Default 270/4096: a 270° single-turn
    /// potentiometer on the steering axis, 1:1, on a 12-bit ADC.
    pub deg_per_count: f32,
    /// Three measured points in increasing `counts`; when present they replace
    /// `center_counts` and `deg_per_count`.
    pub three_point: Option<[CalPoint; 3]>,
    /// Highest ADC reading. Default 4095 (12 bits).
    pub adc_max: u16,
    /// A sample within this many counts of 0 or `adc_max` is saturation.
    /// Default 8.
    pub saturation_margin: u16,
}

impl SteeringCalibration {
    /// The defaults (see each field).
    pub const DEFAULT: Self = Self {
        center_counts: 2048.0,
        deg_per_count: 270.0 / 4096.0,
        three_point: None,
        adc_max: 4095,
        saturation_margin: 8,
    };

    /// The angle for a (mean) ADC reading, degrees.
    #[must_use]
    pub fn deg(&self, counts: f32) -> f32 {
        match self.three_point {
            None => (counts - self.center_counts) * self.deg_per_count,
            Some([a, b, c]) => {
                // Extrapolate beyond the ends along the end segments.
                let (p, q) = if counts < b.counts { (a, b) } else { (b, c) };
                p.deg + (counts - p.counts) * (q.deg - p.deg) / (q.counts - p.counts)
            }
        }
    }
}

impl Default for SteeringCalibration {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// A [`SteeringCalibration`] that cannot work.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum SteeringConfigError {
    /// `center_counts` or `deg_per_count` is not finite, or the gain is zero.
    Linear,
    /// The three points are not finite or not in strictly increasing counts.
    ThreePoint,
    /// The saturation margins cover the whole ADC range.
    Margin,
}

impl fmt::Display for SteeringConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Linear => "steering center and gain must be finite, the gain non-zero",
            Self::ThreePoint => "steering calibration points must be finite with increasing counts",
            Self::Margin => "steering saturation margins leave no usable ADC range",
        })
    }
}

#[cfg(feature = "std")]
impl std::error::Error for SteeringConfigError {}

/// One frame's steering value.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SteeringSample {
    /// Angle, degrees, positive to the left.
    pub deg: f32,
    /// A sample hit either end of the ADC range.
    pub saturated: bool,
}

/// Steering channel: accumulates ADC samples, yields one value per frame.
#[derive(Clone, Debug)]
pub struct Steering {
    cal: SteeringCalibration,
    acc: Boxcar<1>,
    saturated: bool,
}

impl Steering {
    /// A channel with `cal`, or why the calibration cannot work.
    pub fn try_new(cal: SteeringCalibration) -> Result<Self, SteeringConfigError> {
        let finite = cal.center_counts.is_finite() && cal.deg_per_count.is_finite();
        if !finite || cal.deg_per_count == 0.0 {
            return Err(SteeringConfigError::Linear);
        }
        if let Some([a, b, c]) = cal.three_point {
            let all_finite = [a, b, c]
                .iter()
                .all(|p| p.counts.is_finite() && p.deg.is_finite());
            if !all_finite || a.counts >= b.counts || b.counts >= c.counts {
                return Err(SteeringConfigError::ThreePoint);
            }
        }
        if u32::from(cal.saturation_margin) * 2 >= u32::from(cal.adc_max) {
            return Err(SteeringConfigError::Margin);
        }
        Ok(Self {
            cal,
            acc: Boxcar::new(),
            saturated: false,
        })
    }

    /// The calibration in force.
    #[must_use]
    pub const fn calibration(&self) -> &SteeringCalibration {
        &self.cal
    }

    /// Adds one ADC sample.
    pub fn push(&mut self, counts: u16) {
        let margin = self.cal.saturation_margin;
        if counts <= margin || counts >= self.cal.adc_max.saturating_sub(margin) {
            self.saturated = true;
        }
        self.acc.push([i32::from(counts)]);
    }

    /// Adds a block of ADC samples (a DMA half-buffer).
    pub fn push_all(&mut self, samples: &[u16]) {
        for &s in samples {
            self.push(s);
        }
    }

    /// The frame's value from the samples since the previous call; `None` if
    /// the ADC delivered none (the frame marks the channel stale).
    pub fn take(&mut self) -> Option<SteeringSample> {
        let [mean] = self.acc.take()?;
        let saturated = core::mem::take(&mut self.saturated);
        Some(SteeringSample {
            deg: self.cal.deg(mean),
            saturated,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steering(cal: SteeringCalibration) -> Steering {
        Steering::try_new(cal).unwrap()
    }

    #[test]
    fn linear_calibration_of_the_mean() {
        let mut s = steering(SteeringCalibration {
            center_counts: 2000.0,
            deg_per_count: 0.05,
            ..SteeringCalibration::DEFAULT
        });
        s.push_all(&[2100, 2101, 2099, 2100]);
        let v = s.take().unwrap();
        assert!((v.deg - 5.0).abs() < 1e-5);
        assert!(!v.saturated);
        assert_eq!(s.take(), None);
    }

    #[test]
    fn three_point_calibration_is_piecewise_linear() {
        // Left stop at 1000 counts = +40°, centre 2100, right stop 3000 = -35°.
        let cal = SteeringCalibration {
            three_point: Some([
                CalPoint {
                    counts: 1000.0,
                    deg: 40.0,
                },
                CalPoint {
                    counts: 2100.0,
                    deg: 0.0,
                },
                CalPoint {
                    counts: 3000.0,
                    deg: -35.0,
                },
            ]),
            ..SteeringCalibration::DEFAULT
        };
        let close = |c: f32, want: f32| assert!((cal.deg(c) - want).abs() < 1e-4, "{c}");
        close(1000.0, 40.0);
        close(2100.0, 0.0);
        close(3000.0, -35.0);
        close(1550.0, 20.0);
        close(2550.0, -17.5);
        close(3090.0, -38.5); // extrapolated along the last segment
        assert!(Steering::try_new(cal).is_ok());
    }

    #[test]
    fn samples_at_the_rails_mark_the_frame_saturated() {
        let mut s = steering(SteeringCalibration::DEFAULT);
        s.push_all(&[2048, 4095, 2048]);
        assert!(s.take().unwrap().saturated);
        s.push_all(&[2048, 5]);
        assert!(s.take().unwrap().saturated);
        s.push(2048);
        assert!(!s.take().unwrap().saturated);
    }

    #[test]
    fn bad_calibrations_are_refused() {
        let d = SteeringCalibration::DEFAULT;
        let err = |c| Steering::try_new(c).unwrap_err();
        assert_eq!(
            err(SteeringCalibration {
                deg_per_count: 0.0,
                ..d
            }),
            SteeringConfigError::Linear
        );
        let p = |counts| CalPoint { counts, deg: 0.0 };
        assert_eq!(
            err(SteeringCalibration {
                three_point: Some([p(1.0), p(1.0), p(2.0)]),
                ..d
            }),
            SteeringConfigError::ThreePoint
        );
        assert_eq!(
            err(SteeringCalibration {
                saturation_margin: 2048,
                ..d
            }),
            SteeringConfigError::Margin
        );
    }
}
