//! The supply voltage through the internal reference: ADC1 channel 17
//! (VREFINT, ADC1_IN17 only: RM0090, ADC chapter) converted a few times, and the
//! factory's conversion of it read from system memory. What the numbers
//! mean, and whether the brown-out level may be programmed on them, is the
//! core's `supply`.
//!
//! embassy-stm32 0.6.0 (`adc/v2.rs`): `Adc::new` enables and resets the ADC
//! (`rcc::enable_and_reset`, so whatever the steering ring left in its
//! registers is gone) and sets the prescaler from PCLK2 (84 MHz / 4 = 21 MHz);
//! `enable_vrefint` sets TSVREFE in ADC_CCR; `blocking_read` stops the
//! converter, programs a one-channel sequence with the given sample time and
//! waits for EOC. Its `VrefInt::calibrated_value` is not built for the F4
//! (the crate has no VREFINTCAL register for it), so the word is read here.

use embassy_stm32::adc::{Adc, SampleTime, VrefInt};
use embassy_stm32::peripherals::ADC1;
use embassy_stm32::Peri;
use embassy_time::{block_for, Duration};
use wobble_core::supply::{self, SupplyReading, VREFINT_CAL_ADDR};

/// The factory's VREFINT conversion (`supply::VREFINT_CAL_ADDR`).
fn factory_word() -> u16 {
    // SAFETY: a 16-bit-aligned word of the system memory's read-only
    // calibration area (DS8626), always mapped on the STM32F405.
    unsafe { core::ptr::read_volatile(VREFINT_CAL_ADDR as *const u16) }
}

/// Converts VREFINT [`supply::SAMPLES`] times with the longest sample time
/// (480 cycles at 21 MHz: 22.9 µs, over the 10 µs VREFINT needs) and hands
/// the conversions to the core. The ADC is powered down and its clock
/// gated again when `adc` is dropped at the end (`Adc`'s `Drop`).
pub fn measure(adc: Peri<'_, ADC1>) -> Option<SupplyReading> {
    let mut adc = Adc::new(adc);
    let mut vrefint: VrefInt = adc.enable_vrefint();
    // The reference's start-up after TSVREFE (t_START, 10 µs at most).
    block_for(Duration::from_micros(u64::from(supply::VREFINT_SAMPLE_US)));
    let mut samples = [0u16; supply::SAMPLES];
    for s in &mut samples {
        *s = adc.blocking_read(&mut vrefint, SampleTime::CYCLES480);
    }
    supply::measure(&samples, factory_word())
}
