//! 100 Hz frame assembly: the latest value of every channel, with status flags.
//!
//! At each tick the sampler collects what every channel produced since the
//! previous tick (each `take()` returns at once, `None` if nothing came) and
//! hands it to [`FrameAssembler::tick`]. The assembler never waits: a channel
//! with nothing new keeps its previous value and is flagged stale, a channel
//! that never delivered reads zero and is flagged stale, and an IMU that has
//! been silent for `imu_missing_ticks` or is stuck is flagged as a fault.

use crate::format::{
    quantise_i16, quantise_u16, FixMode, Frame, FrameStatus, GpsFix, ACCEL_COUNTS_PER_G,
    EDGE_AGE_NONE, GYRO_COUNTS_PER_DPS, STEER_COUNTS_PER_DEG,
};
use crate::imu::ImuSample;
use crate::steering::SteeringSample;
use crate::wheel::WheelSample;

/// Frame assembly configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameConfig {
    /// Consecutive ticks without an IMU sample after which the IMU counts as
    /// missing (`IMU_FAULT`). Default 10 (100 ms).
    pub imu_missing_ticks: u16,
    /// A GPS fix with a 2D/3D mode older than this is stale (`GPS_STALE`).
    /// Default 1 s.
    pub gps_stale_us: u64,
}

impl FrameConfig {
    /// The defaults (see each field).
    pub const DEFAULT: Self = Self {
        imu_missing_ticks: 10,
        gps_stale_us: 1_000_000,
    };
}

impl Default for FrameConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What each channel produced since the previous tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TickInputs {
    /// The IMU's value for this frame, if it delivered samples.
    pub imu: Option<ImuSample>,
    /// The steering value for this frame, if the ADC delivered samples.
    pub steering: Option<SteeringSample>,
    /// The wheel's state at the tick (always available: it is computed).
    pub wheel: WheelSample,
    /// A GPS fix emitted since the previous tick.
    pub gps_fix: Option<GpsFix>,
    /// The wobble alert is on.
    pub alert: bool,
    /// The marker button is held.
    pub marker: bool,
}

/// Builds one [`Frame`] per tick from the latest channel values.
#[derive(Clone, Debug)]
pub struct FrameAssembler {
    config: FrameConfig,
    imu: Option<ImuSample>,
    ticks_without_imu: u16,
    steering: Option<SteeringSample>,
    last_gps_fix_us: Option<u64>,
}

impl FrameAssembler {
    /// An assembler that has seen no channel yet.
    #[must_use]
    pub const fn new(config: FrameConfig) -> Self {
        Self {
            config,
            imu: None,
            ticks_without_imu: 0,
            steering: None,
            last_gps_fix_us: None,
        }
    }

    /// The frame for the tick at `t_us`.
    pub fn tick(&mut self, t_us: u64, inputs: &TickInputs) -> Frame {
        let mut status = 0u8;

        match inputs.imu {
            Some(s) => {
                self.imu = Some(s);
                self.ticks_without_imu = 0;
            }
            None => {
                status |= FrameStatus::IMU_STALE;
                self.ticks_without_imu = self.ticks_without_imu.saturating_add(1);
            }
        }
        let imu = self.imu.unwrap_or_default();
        let missing = self.imu.is_none() || self.ticks_without_imu >= self.config.imu_missing_ticks;
        if missing || imu.stuck {
            status |= FrameStatus::IMU_FAULT;
        }

        if inputs.steering.is_some() {
            self.steering = inputs.steering;
        } else {
            status |= FrameStatus::STEER_STALE;
        }
        let steering = self.steering.unwrap_or_default();
        if steering.saturated {
            status |= FrameStatus::STEER_SATURATED;
        }

        let wheel = inputs.wheel;
        if wheel.stopped {
            status |= FrameStatus::WHEEL_STOPPED;
        }
        let edge_age_us = wheel
            .last_edge_us
            .map(|e| t_us.saturating_sub(e))
            .and_then(|age| u16::try_from(age).ok())
            .filter(|&age| age != EDGE_AGE_NONE)
            .unwrap_or(EDGE_AGE_NONE);

        if let Some(fix) = inputs.gps_fix.filter(|f| f.fix != FixMode::None) {
            self.last_gps_fix_us = Some(fix.t_us);
        }
        let gps_fresh = self
            .last_gps_fix_us
            .is_some_and(|t| t_us.saturating_sub(t) <= self.config.gps_stale_us);
        if !gps_fresh {
            status |= FrameStatus::GPS_STALE;
        }
        if inputs.alert {
            status |= FrameStatus::ALERT;
        }
        if inputs.marker {
            status |= FrameStatus::MARKER;
        }

        Frame {
            t_us,
            accel: imu.accel_g.map(|g| quantise_i16(g, ACCEL_COUNTS_PER_G)),
            gyro: imu.gyro_dps.map(|r| quantise_i16(r, GYRO_COUNTS_PER_DPS)),
            steer_cdeg: quantise_i16(steering.deg, STEER_COUNTS_PER_DEG),
            // The card keeps the count modulo 2^16: the decoder unwraps it.
            wheel_count: wheel.pulses as u16,
            wheel_edge_age_us: edge_age_us,
            speed_mm_s: quantise_u16(wheel.speed_mps, 1000.0),
            status: FrameStatus(status),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn imu(ax: f32) -> ImuSample {
        ImuSample {
            accel_g: [ax, 0.0, 1.0],
            gyro_dps: [0.0, 0.0, 10.0],
            stuck: false,
        }
    }

    #[test]
    fn fresh_channels_fill_the_frame() {
        let mut a = FrameAssembler::new(FrameConfig::DEFAULT);
        let f = a.tick(
            1_000_000,
            &TickInputs {
                imu: Some(imu(0.5)),
                steering: Some(SteeringSample {
                    deg: -3.25,
                    saturated: false,
                }),
                wheel: WheelSample {
                    pulses: 70_000,
                    last_edge_us: Some(990_000),
                    speed_mps: 4.2,
                    stopped: false,
                },
                gps_fix: Some(GpsFix {
                    t_us: 950_000,
                    fix: FixMode::Fix3d,
                    ..GpsFix::default()
                }),
                alert: true,
                marker: false,
            },
        );
        assert_eq!(f.accel, [1024, 0, 2048]);
        assert_eq!(f.gyro, [0, 0, 320]);
        assert_eq!(f.steer_cdeg, -325);
        assert_eq!(f.wheel_count, (70_000 % 65_536) as u16);
        assert_eq!(f.wheel_edge_age_us, 10_000);
        assert_eq!(f.speed_mm_s, 4200);
        assert_eq!(f.status, FrameStatus(FrameStatus::ALERT));
    }

    #[test]
    fn missing_channels_hold_their_value_and_are_flagged() {
        let mut a = FrameAssembler::new(FrameConfig::DEFAULT);
        let first = a.tick(
            0,
            &TickInputs {
                imu: Some(imu(0.25)),
                steering: Some(SteeringSample {
                    deg: 45.0,
                    saturated: true,
                }),
                ..TickInputs::default()
            },
        );
        let s = first.status;
        assert!(s.has(FrameStatus::STEER_SATURATED | FrameStatus::GPS_STALE));
        assert!(!s.has(FrameStatus::WHEEL_STOPPED));
        assert_eq!(first.wheel_edge_age_us, EDGE_AGE_NONE);

        // Nine empty ticks: held values, stale, no fault yet.
        for i in 1..10 {
            let f = a.tick(i * 10_000, &TickInputs::default());
            assert_eq!(f.accel, first.accel);
            assert_eq!(f.steer_cdeg, 4500);
            assert!(f
                .status
                .has(FrameStatus::IMU_STALE | FrameStatus::STEER_STALE));
            assert!(f.status.has(FrameStatus::STEER_SATURATED));
            assert!(!f.status.has(FrameStatus::IMU_FAULT), "tick {i}");
        }
        // The tenth without an IMU sample: missing.
        let f = a.tick(100_000, &TickInputs::default());
        assert!(f.status.has(FrameStatus::IMU_FAULT));
        // It comes back.
        let f = a.tick(
            110_000,
            &TickInputs {
                imu: Some(imu(0.0)),
                ..TickInputs::default()
            },
        );
        assert!(!f
            .status
            .has(FrameStatus::IMU_FAULT | FrameStatus::IMU_STALE));
    }

    #[test]
    fn never_seen_channels_read_zero_and_stale() {
        let mut a = FrameAssembler::new(FrameConfig::DEFAULT);
        let f = a.tick(0, &TickInputs::default());
        assert_eq!((f.accel, f.gyro, f.steer_cdeg), ([0; 3], [0; 3], 0));
        for bit in [
            FrameStatus::IMU_STALE,
            FrameStatus::IMU_FAULT,
            FrameStatus::STEER_STALE,
            FrameStatus::GPS_STALE,
        ] {
            assert!(f.status.has(bit), "{bit:#x}");
        }
    }

    #[test]
    fn stuck_imu_is_a_fault() {
        let mut a = FrameAssembler::new(FrameConfig::DEFAULT);
        let stuck = ImuSample {
            stuck: true,
            ..imu(0.0)
        };
        let f = a.tick(
            0,
            &TickInputs {
                imu: Some(stuck),
                ..TickInputs::default()
            },
        );
        assert!(f.status.has(FrameStatus::IMU_FAULT));
        assert!(!f.status.has(FrameStatus::IMU_STALE));
    }

    #[test]
    fn gps_goes_stale_a_second_after_the_last_real_fix() {
        let mut a = FrameAssembler::new(FrameConfig::DEFAULT);
        let fix = |t_us, fix| TickInputs {
            gps_fix: Some(GpsFix {
                t_us,
                fix,
                ..GpsFix::default()
            }),
            ..TickInputs::default()
        };
        assert!(!a
            .tick(10_000, &fix(0, FixMode::Fix2d))
            .status
            .has(FrameStatus::GPS_STALE));
        // A fix without a mode does not refresh it.
        let f = a.tick(1_000_000, &fix(990_000, FixMode::None));
        assert!(!f.status.has(FrameStatus::GPS_STALE));
        let f = a.tick(1_000_001, &TickInputs::default());
        assert!(f.status.has(FrameStatus::GPS_STALE));
    }

    #[test]
    fn wheel_flags_and_edge_age_limits() {
        let mut a = FrameAssembler::new(FrameConfig::DEFAULT);
        let wheel = |last, stopped| TickInputs {
            wheel: WheelSample {
                pulses: 3,
                last_edge_us: Some(last),
                speed_mps: 0.0,
                stopped,
            },
            ..TickInputs::default()
        };
        let f = a.tick(100_000, &wheel(100_000 - 65_534, false));
        assert_eq!(f.wheel_edge_age_us, 65_534);
        let f = a.tick(100_000, &wheel(100_000 - 65_535, false));
        assert_eq!(f.wheel_edge_age_us, EDGE_AGE_NONE);
        let f = a.tick(900_000, &wheel(0, true));
        assert!(f.status.has(FrameStatus::WHEEL_STOPPED));
    }
}
