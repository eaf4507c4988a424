//! HAL-free core of the wobble logger.
//!
//! Everything that is logic lives here and runs unchanged on the STM32F405,
//! in the QEMU image and on the host: the card format (encoder and decoder),
//! sensor ingestion, the wobble detector and the logger state machine. No HAL
//! types appear in this crate; boards plug peripherals in through traits.
#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![warn(missing_docs)]

pub mod adc_ring;
pub mod app;
pub mod boot;
pub mod channels;
pub mod config;
pub mod decimate;
pub mod detector;
pub mod drivers;
pub mod faults;
pub mod format;
pub mod frame_assembly;
pub mod gps;
pub mod imu;
pub mod imu_clock;
pub mod logger;
pub mod selftest;
pub mod stall;
pub mod steering;
pub mod supply;
pub mod watchdog;
pub mod wheel;
pub mod wheel_capture;
