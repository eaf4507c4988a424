//! IMU: raw register values -> g and deg/s in the bicycle frame.
//!
//! The driver reads the six 16-bit output registers (accelerometer x/y/z,
//! gyroscope x/y/z) at the IMU's output data rate and pushes them here. Each
//! frame takes the mean of the samples since the previous frame (see
//! [`crate::decimate`]; the IMU's own digital low-pass filter should also be
//! set below 50 Hz), scaled by the datasheet sensitivity of the configured
//! range and rotated from the sensor's axes to the bicycle's.
//!
//! Bicycle frame (ISO 8855, as the steering angle's sign): x forward, y to
//! the left, z up. The mounting is given as an [`AxisMap`]: for each bicycle
//! axis, the sensor axis that points along it and its sign. Only proper
//! rotations are accepted; a mirror image (a typo in the configuration) would
//! silently flip the sign of roll or yaw rate.
//!
//! A sensor that returns exactly the same six values sample after sample is
//! stuck (a hung bus returning a stale buffer, a sensor in reset): real MEMS
//! noise changes some of the six values on every sample.

use core::fmt;

use crate::decimate::Boxcar;

/// One sensor axis with a sign.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SignedAxis {
    /// Sensor +x.
    PosX,
    /// Sensor −x.
    NegX,
    /// Sensor +y.
    PosY,
    /// Sensor −y.
    NegY,
    /// Sensor +z.
    PosZ,
    /// Sensor −z.
    NegZ,
}

impl SignedAxis {
    const fn index(self) -> usize {
        match self {
            Self::PosX | Self::NegX => 0,
            Self::PosY | Self::NegY => 1,
            Self::PosZ | Self::NegZ => 2,
        }
    }

    const fn negative(self) -> bool {
        matches!(self, Self::NegX | Self::NegY | Self::NegZ)
    }
}

/// For each bicycle axis (x forward, y left, z up), the sensor axis along it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AxisMap(pub [SignedAxis; 3]);

impl AxisMap {
    /// Sensor axes are the bicycle's.
    pub const IDENTITY: Self = Self([SignedAxis::PosX, SignedAxis::PosY, SignedAxis::PosZ]);

    /// Whether this is a proper rotation: each sensor axis used once and the
    /// determinant +1 (right-handed in, right-handed out).
    #[must_use]
    pub fn is_rotation(&self) -> bool {
        let [a, b, c] = self.0.map(SignedAxis::index);
        if a == b || b == c || a == c {
            return false;
        }
        // Sign of the permutation: even for cyclic shifts of (0, 1, 2).
        let even = (b + 3 - a) % 3 == 1;
        let negatives = self.0.iter().filter(|s| s.negative()).count();
        even == (negatives % 2 == 0)
    }

    /// Applies the map to a sensor-frame vector.
    #[must_use]
    pub fn apply(&self, v: [f32; 3]) -> [f32; 3] {
        self.0.map(|s| {
            let x = v[s.index()];
            if s.negative() {
                -x
            } else {
                x
            }
        })
    }
}

impl Default for AxisMap {
    fn default() -> Self {
        Self::IDENTITY
    }
}

/// IMU configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ImuConfig {
    /// Accelerometer sensitivity for the configured range, g per LSB, from the
    /// datasheet. Default ±16 g over the 16-bit range: 16/32768.
    pub accel_g_per_lsb: f32,
    /// Gyroscope sensitivity for the configured range, deg/s per LSB, from
    /// the datasheet (ST parts differ from range/32768: 17.5 mdps/LSB at
    /// ±500 deg/s). Default ±500 deg/s over the 16-bit range: 500/32768.
    pub gyro_dps_per_lsb: f32,
    /// Mounting of the sensor on the bicycle.
    pub axis_map: AxisMap,
    /// This many identical consecutive raw samples mean the IMU is stuck.
    /// Default 50; 0 disables the check.
    pub stuck_samples: u16,
}

impl ImuConfig {
    /// Smallest accelerometer range the wobble measurements need, g.
    pub const MIN_ACCEL_RANGE_G: f32 = 10.0;
    /// Smallest gyroscope range the wobble measurements need, deg/s.
    pub const MIN_GYRO_RANGE_DPS: f32 = 300.0;

    /// The defaults (see each field).
    pub const DEFAULT: Self = Self::with_ranges(16, 500);

    /// The defaults with sensitivities of range/32768 (the InvenSense and
    /// Bosch convention) for ±`accel_g` and ±`gyro_dps`.
    #[must_use]
    pub const fn with_ranges(accel_g: u16, gyro_dps: u16) -> Self {
        Self {
            accel_g_per_lsb: accel_g as f32 / 32768.0,
            gyro_dps_per_lsb: gyro_dps as f32 / 32768.0,
            axis_map: AxisMap::IDENTITY,
            stuck_samples: 50,
        }
    }

    /// The accelerometer's full-scale range, ±g.
    #[must_use]
    pub fn accel_range_g(&self) -> f32 {
        self.accel_g_per_lsb * 32767.0
    }

    /// The gyroscope's full-scale range, ±deg/s.
    #[must_use]
    pub fn gyro_range_dps(&self) -> f32 {
        self.gyro_dps_per_lsb * 32767.0
    }
}

impl Default for ImuConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// An [`ImuConfig`] that cannot work.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum ImuConfigError {
    /// The accelerometer range is below ±10 g (or not a number).
    AccelRange,
    /// The gyroscope range is below ±300 deg/s (or not a number).
    GyroRange,
    /// The axis map is not a proper rotation.
    AxisMap,
}

impl fmt::Display for ImuConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::AccelRange => "IMU accelerometer range must be at least ±10 g",
            Self::GyroRange => "IMU gyroscope range must be at least ±300 deg/s",
            Self::AxisMap => "IMU axis map must be a rotation (each axis once, no mirror image)",
        })
    }
}

#[cfg(feature = "std")]
impl std::error::Error for ImuConfigError {}

/// The six output registers of one IMU sample, in sensor axes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RawImu {
    /// Accelerometer x/y/z, LSB.
    pub accel: [i16; 3],
    /// Gyroscope x/y/z, LSB.
    pub gyro: [i16; 3],
}

/// One frame's IMU value, in the bicycle frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ImuSample {
    /// Acceleration x/y/z, g.
    pub accel_g: [f32; 3],
    /// Angular rate x/y/z, deg/s.
    pub gyro_dps: [f32; 3],
    /// The sensor repeated identical samples: its values are not live.
    pub stuck: bool,
    /// Samples the sensor made since the previous frame that reach no
    /// frame ([`crate::imu_clock`]): each is a counted IMU fault.
    pub skipped: u16,
}

/// IMU channel: accumulates raw samples, yields one value per frame.
#[derive(Clone, Debug)]
pub struct Imu {
    config: ImuConfig,
    acc: Boxcar<6>,
    last: Option<RawImu>,
    repeats: u16,
}

impl Imu {
    /// A channel for `config`, or why the configuration cannot work.
    pub fn try_new(config: ImuConfig) -> Result<Self, ImuConfigError> {
        let at_least = |x: f32, min: f32| x.is_finite() && x >= min;
        if !at_least(config.accel_range_g(), ImuConfig::MIN_ACCEL_RANGE_G) {
            return Err(ImuConfigError::AccelRange);
        }
        if !at_least(config.gyro_range_dps(), ImuConfig::MIN_GYRO_RANGE_DPS) {
            return Err(ImuConfigError::GyroRange);
        }
        if !config.axis_map.is_rotation() {
            return Err(ImuConfigError::AxisMap);
        }
        Ok(Self {
            config,
            acc: Boxcar::new(),
            last: None,
            repeats: 0,
        })
    }

    /// The configuration in force.
    #[must_use]
    pub const fn config(&self) -> &ImuConfig {
        &self.config
    }

    /// Adds one raw sample.
    pub fn push(&mut self, raw: RawImu) {
        self.watch(raw);
        let [ax, ay, az] = raw.accel.map(i32::from);
        let [gx, gy, gz] = raw.gyro.map(i32::from);
        self.acc.push([ax, ay, az, gx, gy, gz]);
    }

    /// Counts one raw sample towards the stuck check only (samples placed
    /// in time by [`crate::imu_clock`] are combined there, not here).
    pub fn watch(&mut self, raw: RawImu) {
        if self.last == Some(raw) {
            self.repeats = self.repeats.saturating_add(1);
        } else {
            self.repeats = 0;
        }
        self.last = Some(raw);
    }

    /// The frame's value from the samples since the previous call; `None` if
    /// the IMU delivered none (the frame marks the channel stale).
    pub fn take(&mut self) -> Option<ImuSample> {
        self.acc.take().map(|counts| self.scale(counts))
    }

    /// A frame's value from the six axes in sensor counts (accel x/y/z,
    /// gyro x/y/z): scaled, rotated, and marked stuck if the samples
    /// watched lately were.
    #[must_use]
    pub fn scale(&self, counts: [f32; 6]) -> ImuSample {
        let [ax, ay, az, gx, gy, gz] = counts;
        let c = &self.config;
        ImuSample {
            accel_g: c
                .axis_map
                .apply([ax, ay, az].map(|x| x * c.accel_g_per_lsb)),
            gyro_dps: c
                .axis_map
                .apply([gx, gy, gz].map(|x| x * c.gyro_dps_per_lsb)),
            stuck: c.stuck_samples != 0 && self.repeats.saturating_add(1) >= c.stuck_samples,
            skipped: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use SignedAxis::*;

    #[test]
    fn scales_to_g_and_dps() {
        let mut imu = Imu::try_new(ImuConfig::DEFAULT).unwrap();
        imu.push(RawImu {
            accel: [2048, -2048, 32767],
            gyro: [6554, -65, 0],
        });
        let s = imu.take().unwrap();
        assert_eq!(s.accel_g[0], 1.0);
        assert_eq!(s.accel_g[1], -1.0);
        assert!((s.accel_g[2] - 16.0).abs() < 1e-3);
        assert!((s.gyro_dps[0] - 100.0).abs() < 0.01);
        assert!((s.gyro_dps[1] + 0.99).abs() < 0.01);
        assert!(!s.stuck);
        assert_eq!(imu.take(), None);
    }

    #[test]
    fn datasheet_sensitivity_is_used_as_given() {
        // An ST gyro at ±500 deg/s: 17.5 mdps/LSB.
        let mut imu = Imu::try_new(ImuConfig {
            gyro_dps_per_lsb: 0.0175,
            ..ImuConfig::DEFAULT
        })
        .unwrap();
        imu.push(RawImu {
            accel: [0; 3],
            gyro: [10_000, 0, 0],
        });
        assert!((imu.take().unwrap().gyro_dps[0] - 175.0).abs() < 1e-3);
    }

    #[test]
    fn axis_map_rotates_into_the_bicycle_frame() {
        // Sensor mounted with its x to the left and its y backwards, z up:
        // bicycle x (forward) = sensor −y, bicycle y (left) = sensor +x.
        let map = AxisMap([NegY, PosX, PosZ]);
        assert!(map.is_rotation());
        let mut imu = Imu::try_new(ImuConfig {
            axis_map: map,
            ..ImuConfig::DEFAULT
        })
        .unwrap();
        imu.push(RawImu {
            accel: [100, 200, 300],
            gyro: [1, 2, 3],
        });
        let s = imu.take().unwrap();
        let g = 16.0 / 32768.0;
        assert_eq!(s.accel_g, [-200.0 * g, 100.0 * g, 300.0 * g]);
    }

    #[test]
    fn only_rotations_are_accepted() {
        let rotations = [
            [PosX, PosY, PosZ],
            [PosY, PosZ, PosX],
            [NegX, NegY, PosZ],
            [PosY, PosX, NegZ],
            [NegZ, PosY, PosX],
        ];
        for r in rotations {
            assert!(AxisMap(r).is_rotation(), "{r:?}");
        }
        let not = [
            [PosX, PosY, NegZ], // mirror
            [PosY, PosX, PosZ], // mirror
            [PosX, PosX, PosZ], // axis twice
            [NegX, NegY, NegZ], // point reflection
        ];
        for r in not {
            assert!(!AxisMap(r).is_rotation(), "{r:?}");
            let cfg = ImuConfig {
                axis_map: AxisMap(r),
                ..ImuConfig::DEFAULT
            };
            assert_eq!(Imu::try_new(cfg).unwrap_err(), ImuConfigError::AxisMap);
        }
    }

    #[test]
    fn ranges_below_the_paper_are_refused() {
        let err = |c| Imu::try_new(c).unwrap_err();
        assert_eq!(
            err(ImuConfig::with_ranges(8, 500)),
            ImuConfigError::AccelRange
        );
        assert_eq!(
            err(ImuConfig::with_ranges(16, 250)),
            ImuConfigError::GyroRange
        );
        assert!(Imu::try_new(ImuConfig::with_ranges(16, 2000)).is_ok());
    }

    #[test]
    fn identical_samples_mean_stuck() {
        let mut imu = Imu::try_new(ImuConfig::DEFAULT).unwrap();
        let raw = RawImu {
            accel: [1, 2, 3],
            gyro: [4, 5, 6],
        };
        for _ in 0..49 {
            imu.push(raw);
        }
        assert!(!imu.take().unwrap().stuck);
        imu.push(raw);
        assert!(imu.take().unwrap().stuck);
        imu.push(RawImu {
            accel: [1, 2, 4],
            ..raw
        });
        assert!(!imu.take().unwrap().stuck);
    }
}
