//! The steering potentiometer: ADC1 converting continuously into a DMA ring
//! buffer; each frame averages what arrived since the previous one through
//! the core's calibration.

use embassy_stm32::adc::RingBufferedAdc;
use embassy_stm32::peripherals::ADC1;
use wobble_core::app::ports::{SensorError, SteeringPort, SteeringSample};
use wobble_core::steering::Steering;

/// Conversions per frame, at most: 21 MHz ADC clock / (480 + 12 cycles)
/// = 42.7 kHz, 427 per 10 ms frame (see `firmware/docs/board.md`).
pub const FRAME_SAMPLES: usize = 448;
/// DMA ring: two frames' worth, so a late tick loses nothing.
pub const DMA_SAMPLES: usize = 2 * FRAME_SAMPLES;

/// ADC ring buffer plus the core's steering channel.
pub struct SteeringAdapter {
    adc: RingBufferedAdc<'static, ADC1>,
    channel: Steering,
    frame: [u16; FRAME_SAMPLES],
}

impl SteeringAdapter {
    /// Starts the conversions.
    pub fn new(mut adc: RingBufferedAdc<'static, ADC1>, channel: Steering) -> Self {
        adc.start();
        Self {
            adc,
            channel,
            frame: [0; FRAME_SAMPLES],
        }
    }
}

impl SteeringPort for SteeringAdapter {
    async fn read(&mut self) -> Result<SteeringSample, SensorError> {
        let n = self.adc.read_latest(&mut self.frame);
        self.channel
            .push_all(self.frame.get(..n).unwrap_or_default());
        // No conversion since the last frame: the DMA ring stopped.
        self.channel.take().ok_or(SensorError::Stale)
    }
}
