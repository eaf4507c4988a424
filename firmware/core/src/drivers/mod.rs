//! Drivers for the parts on the logger board, written against the
//! `embedded-hal(-async)` traits only, so they are tested on the host with
//! mocked buses and run unchanged on any MCU.

pub mod gnss_bringup;
pub mod gnss_setup;
pub mod icm42688;
pub mod sd_spi;
pub mod sdcard;
