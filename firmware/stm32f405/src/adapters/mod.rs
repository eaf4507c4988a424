//! The core's port traits implemented with embassy-stm32 drivers. Each
//! adapter only moves data between a peripheral and the core: the
//! calibration, filtering and fault logic are the core's.

pub mod card;
pub mod gps;
pub mod imu;
pub mod rider;
pub mod steering;
pub mod supply;
pub mod wheel;
