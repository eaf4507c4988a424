//! The longest time the sampling task can go without reading its sensors,
//! and the hardware ring buffers sized for it, so that a stall costs no
//! sample.
//!
//! The sampler awaits the IMU driver, and an IMU re-initialisation (after a
//! failure, at most once a second) waits for the sensor's reset and
//! start-up: 46 ms, four and a half frames. Meanwhile the ADC keeps
//! converting into its DMA ring and the wheel timer keeps capturing; both
//! must hold everything that arrives until the sampler is back.

use crate::app::sampler::FRAME_PERIOD_US;
use crate::drivers::icm42688::{RESET_WAIT_US, STARTUP_WAIT_US};

/// Headroom over the waits themselves: the SPI traffic of the
/// configuration sequence, the other sensors' reads, a late tick.
const MARGIN_US: u32 = 10_000;

/// The longest stall of the sampler, µs: an IMU re-initialisation plus one
/// frame (the read that follows it) and [`MARGIN_US`].
pub const LONGEST_STALL_US: u32 =
    RESET_WAIT_US + STARTUP_WAIT_US + FRAME_PERIOD_US as u32 + MARGIN_US;

/// Samples a ring filled at `rate_hz` needs to bridge [`LONGEST_STALL_US`],
/// rounded up to a multiple of `align` (a DMA transfer count that splits
/// evenly into half-transfer interrupts).
#[must_use]
pub const fn ring_samples(rate_hz: u32, align: usize) -> usize {
    let samples = (rate_hz as u64 * LONGEST_STALL_US as u64).div_ceil(1_000_000) as usize;
    samples.div_ceil(align) * align
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stall_covers_an_imu_reinitialisation_and_a_frame() {
        assert_eq!(LONGEST_STALL_US, 66_000);
    }

    #[test]
    fn rings_hold_the_whole_stall() {
        // ADC1 at 21 MHz / (480 + 12) cycles.
        let adc_hz = 21_000_000 / 492;
        let n = ring_samples(adc_hz, 2);
        assert_eq!(n, 2818);
        assert!(n as u64 * 1_000_000 >= u64::from(adc_hz) * u64::from(LONGEST_STALL_US));
        assert_eq!(ring_samples(1_000, 64), 128);
        assert_eq!(ring_samples(0, 1), 0);
    }
}
