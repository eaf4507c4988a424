//! 100 Hz frame assembly: the latest value of every channel, with status flags.
//!
//! At each tick the sampler ([`crate::app::sampler`]) reads every sensor port
//! once (each read returns at once: a channel value, or why there is none)
//! and hands the results to [`FrameAssembler::tick`]. This is the one place
//! that turns channel values into a [`Frame`]: held values, status bits and
//! quantisation to the card's units. The assembler never waits: a channel
//! with nothing new keeps its previous value and is flagged stale, and a
//! channel that never delivered reads zero and is flagged stale.
//!
//! `IMU_FAULT` means the IMU is missing or stuck, which is any of:
//! - it did not answer this tick ([`SensorError::NoResponse`]: bus timeout,
//!   NACK, wrong identity): nothing is coming, so the frame says so at once;
//! - it answered but has delivered no new sample for `imu_missing_ticks`
//!   ticks in a row, or never delivered one: a sensor that stays on the bus
//!   but stopped sampling (a few late samples are only stale);
//! - its sample is stuck (identical raw values, see [`crate::imu`]).
//!
//! `GPS_STALE` is computed from the local time of the last fix with a
//! position, which the GPS task publishes (see
//! [`crate::channels::SharedStatus`]), so the rule does not depend on which
//! task sees the fix.
//!
//! `ALERT` is not set here: the detector runs on the assembled frame's
//! steering (exactly what the card stores, so replaying a log through the
//! host's detector gives the same alerts), and the sampler sets the bit
//! once it has.

use crate::app::ports::SensorError;
use crate::format::{
    quantise_i16, quantise_u16, Frame, FrameStatus, ACCEL_COUNTS_PER_G, EDGE_AGE_NONE,
    GYRO_COUNTS_PER_DPS, STEER_COUNTS_PER_DEG,
};
use crate::imu::ImuSample;
use crate::steering::SteeringSample;
use crate::wheel::WheelSample;

/// Frame assembly configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameConfig {
    /// Consecutive ticks without a new IMU sample after which the IMU counts
    /// as missing (`IMU_FAULT`) even though it answers. Default 10 (100 ms).
    pub imu_missing_ticks: u16,
    /// The GPS is stale (`GPS_STALE`) when its last fix with a position is
    /// older than this. Default 1 s.
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
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TickInputs {
    /// The IMU's value for this frame, or why there is none.
    pub imu: Result<ImuSample, SensorError>,
    /// The steering value for this frame, or why there is none.
    pub steering: Result<SteeringSample, SensorError>,
    /// The wheel's state at the tick (always available: it is computed).
    pub wheel: WheelSample,
    /// Local time of the last GPS fix with a position, µs since boot; `None`
    /// before the first.
    pub last_gps_fix_us: Option<u64>,
    /// The marker button is held.
    pub marker: bool,
}

impl Default for TickInputs {
    /// Nothing delivered: both sensors stale, a default wheel state, no GPS
    /// fix, no marker.
    fn default() -> Self {
        Self {
            imu: Err(SensorError::Stale),
            steering: Err(SensorError::Stale),
            wheel: WheelSample::default(),
            last_gps_fix_us: None,
            marker: false,
        }
    }
}

/// Builds one [`Frame`] per tick from the latest channel values.
#[derive(Clone, Debug)]
pub struct FrameAssembler {
    config: FrameConfig,
    imu: Option<ImuSample>,
    ticks_without_imu: u16,
    steering: Option<SteeringSample>,
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
        }
    }

    /// The frame for the tick at `t_us` (without `ALERT`, see the module
    /// docs).
    pub fn tick(&mut self, t_us: u64, inputs: &TickInputs) -> Frame {
        let mut status = 0u8;

        match inputs.imu {
            Ok(s) => {
                self.imu = Some(s);
                self.ticks_without_imu = 0;
            }
            Err(e) => {
                status |= FrameStatus::IMU_STALE;
                if e == SensorError::NoResponse {
                    status |= FrameStatus::IMU_FAULT;
                }
                self.ticks_without_imu = self.ticks_without_imu.saturating_add(1);
            }
        }
        let imu = self.imu.unwrap_or_default();
        let missing = self.imu.is_none() || self.ticks_without_imu >= self.config.imu_missing_ticks;
        if missing || imu.stuck {
            status |= FrameStatus::IMU_FAULT;
        }

        if let Ok(s) = inputs.steering {
            self.steering = Some(s);
        } else {
            status |= FrameStatus::STEER_STALE;
        }
        let steering = self.steering.unwrap_or_default();
        if steering.saturated {
            status |= FrameStatus::STEER_SATURATED;
        }

        let wheel = &inputs.wheel;
        if wheel.stopped {
            status |= FrameStatus::WHEEL_STOPPED;
        }
        let edge_age_us = wheel
            .last_edge_us
            .map(|e| t_us.saturating_sub(e))
            .and_then(|age| u16::try_from(age).ok())
            .filter(|&age| age != EDGE_AGE_NONE)
            .unwrap_or(EDGE_AGE_NONE);

        let gps_fresh = inputs
            .last_gps_fix_us
            .is_some_and(|t| t_us.saturating_sub(t) <= self.config.gps_stale_us);
        if !gps_fresh {
            status |= FrameStatus::GPS_STALE;
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
            skipped: 0,
        }
    }

    #[test]
    fn fresh_channels_fill_the_frame() {
        let mut a = FrameAssembler::new(FrameConfig::DEFAULT);
        let f = a.tick(
            1_000_000,
            &TickInputs {
                imu: Ok(imu(0.5)),
                steering: Ok(SteeringSample {
                    deg: -3.25,
                    saturated: false,
                }),
                wheel: WheelSample {
                    pulses: 70_000,
                    last_edge_us: Some(990_000),
                    speed_mps: 4.2,
                    stopped: false,
                },
                last_gps_fix_us: Some(950_000),
                marker: true,
            },
        );
        assert_eq!(f.accel, [1024, 0, 2048]);
        assert_eq!(f.gyro, [0, 0, 320]);
        assert_eq!(f.steer_cdeg, -325);
        assert_eq!(f.wheel_count, (70_000 % 65_536) as u16);
        assert_eq!(f.wheel_edge_age_us, 10_000);
        assert_eq!(f.speed_mm_s, 4200);
        assert_eq!(f.status, FrameStatus(FrameStatus::MARKER));
    }

    #[test]
    fn missing_channels_hold_their_value_and_are_flagged() {
        let mut a = FrameAssembler::new(FrameConfig::DEFAULT);
        let first = a.tick(
            0,
            &TickInputs {
                imu: Ok(imu(0.25)),
                steering: Ok(SteeringSample {
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
                imu: Ok(imu(0.0)),
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
                imu: Ok(stuck),
                ..TickInputs::default()
            },
        );
        assert!(f.status.has(FrameStatus::IMU_FAULT));
        assert!(!f.status.has(FrameStatus::IMU_STALE));
    }

    #[test]
    fn an_imu_that_does_not_answer_is_a_fault_at_once() {
        let mut a = FrameAssembler::new(FrameConfig::DEFAULT);
        let answered = TickInputs {
            imu: Ok(imu(0.5)),
            ..TickInputs::default()
        };
        assert!(!a.tick(0, &answered).status.has(FrameStatus::IMU_FAULT));
        let f = a.tick(
            10_000,
            &TickInputs {
                imu: Err(SensorError::NoResponse),
                ..TickInputs::default()
            },
        );
        assert!(f
            .status
            .has(FrameStatus::IMU_STALE | FrameStatus::IMU_FAULT));
        // The last value is held, as for a late sample.
        assert_eq!(f.accel[0], 1024);
        // An answer without a new sample is only stale.
        let f = a.tick(20_000, &TickInputs::default());
        assert!(f.status.has(FrameStatus::IMU_STALE));
        assert!(!f.status.has(FrameStatus::IMU_FAULT));
    }

    #[test]
    fn gps_goes_stale_a_second_after_the_last_fix() {
        let mut a = FrameAssembler::new(FrameConfig::DEFAULT);
        let fix_at = |t_us| TickInputs {
            last_gps_fix_us: Some(t_us),
            ..TickInputs::default()
        };
        assert!(!a
            .tick(10_000, &fix_at(0))
            .status
            .has(FrameStatus::GPS_STALE));
        let f = a.tick(1_000_000, &fix_at(0));
        assert!(!f.status.has(FrameStatus::GPS_STALE));
        let f = a.tick(1_000_001, &fix_at(0));
        assert!(f.status.has(FrameStatus::GPS_STALE));
        // A fix stamped after the tick (a task preempted between the two
        // clock reads) is fresh, not a wrapped age.
        let f = a.tick(2_000_000, &fix_at(2_000_500));
        assert!(!f.status.has(FrameStatus::GPS_STALE));
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
