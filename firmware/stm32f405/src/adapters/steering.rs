//! The steering potentiometer: ADC1 converting continuously into a DMA ring
//! buffer; each frame averages what arrived since the previous one through
//! the core's calibration.

use embassy_stm32::adc::RingBufferedAdc;
use embassy_stm32::pac;
use embassy_stm32::peripherals::ADC1;
use wobble_core::app::ports::{SensorError, SteeringPort, SteeringSample};
use wobble_core::stall;
use wobble_core::steering::Steering;

/// Conversions per second: 21 MHz ADC clock / (480 + 12 cycles), 427 per
/// 10 ms frame (see `firmware/docs/board.md`).
pub const CONVERSIONS_HZ: u32 = 21_000_000 / 492;
/// Conversions per frame, at most (the newest are used).
pub const FRAME_SAMPLES: usize = 448;
/// DMA ring: the sampler's longest stall (an IMU re-initialisation, 46 ms,
/// plus a frame and margin: 66 ms, 2818 samples), so a stall loses nothing.
pub const DMA_SAMPLES: usize = stall::ring_samples(CONVERSIONS_HZ, 2);
const _: () = assert!(DMA_SAMPLES >= 2 * FRAME_SAMPLES);

/// ADC ring buffer plus the core's steering channel.
pub struct SteeringAdapter {
    adc: RingBufferedAdc<'static, ADC1>,
    channel: Steering,
    frame: [u16; FRAME_SAMPLES],
    /// Lowest and highest raw count of the last frame (the self-test's).
    last_range: Option<(u16, u16)>,
}

impl SteeringAdapter {
    /// Starts the conversions.
    pub fn new(mut adc: RingBufferedAdc<'static, ADC1>, channel: Steering) -> Self {
        adc.start();
        Self {
            adc,
            channel,
            frame: [0; FRAME_SAMPLES],
            last_range: None,
        }
    }

    /// Lowest and highest raw ADC count of the last frame read.
    pub fn last_range(&self) -> Option<(u16, u16)> {
        self.last_range
    }

    /// After an overrun (OVR: a conversion not taken by the DMA in time) the
    /// ADC stops issuing DMA requests for good. RM0090 13.8.1: set the DMA
    /// up again, clear OVR, trigger the conversions.
    fn restart(&mut self) {
        self.adc.stop();
        self.adc.clear();
        pac::ADC1.sr().modify(|w| w.set_ovr(false));
        self.adc.start();
    }
}

impl SteeringPort for SteeringAdapter {
    async fn read(&mut self) -> Result<SteeringSample, SensorError> {
        if pac::ADC1.sr().read().ovr() {
            defmt::warn!("steering ADC overrun: restarted");
            self.restart();
            return Err(SensorError::Overrun);
        }
        let n = self.adc.read_latest(&mut self.frame);
        let samples = self.frame.get(..n).unwrap_or_default();
        self.last_range = samples
            .iter()
            .min()
            .zip(samples.iter().max())
            .map(|(&lo, &hi)| (lo, hi));
        self.channel.push_all(samples);
        // No conversion since the last frame: the DMA ring stopped.
        self.channel.take().ok_or(SensorError::Stale)
    }
}
