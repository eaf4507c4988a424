//! The firmware's tasks, written against the port traits of [`ports`] and
//! shared by the STM32 board and the QEMU image.
//!
//! ```text
//!  sensors ─> sampler::run (100 Hz, high-priority executor) ─┐
//!                                                            ├─> RecordQueue ─> writer::run (thread mode) ─> card
//!  GPS UART ─> gps::run (medium-priority executor) ──────────┘
//! ```

pub mod gps;
pub mod gps_setup;
pub mod imu_port;
pub mod ports;
pub mod sampler;
pub mod writer;
