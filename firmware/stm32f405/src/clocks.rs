//! Clock tree: 168 MHz from an 8 MHz crystal.
//!
//! ```text
//! HSE 8 MHz ─/M 4─> 2 MHz ─×N 168─> VCO 336 MHz ─┬─/P 2─> SYSCLK 168 MHz ─> AHB /1 = 168 MHz
//!                                                 └─/Q 7─> 48 MHz (USB/SDIO, unused)
//! APB1 = 168 / 4 = 42 MHz (USART2, SPI2, TIM3/TIM5 at 2 × 42 = 84 MHz)
//! APB2 = 168 / 2 = 84 MHz (SPI1, ADC1 at 84 / 4 = 21 MHz)
//! ```
//!
//! - The VCO input must be 1-2 MHz (2 MHz gives the least jitter) and the
//!   VCO 100-432 MHz; the 48 MHz output must be exact for USB, so Q = 7.
//! - APB1 may not exceed 42 MHz, APB2 84 MHz (datasheet limits).
//! - TIM5 (wheel capture) divides its 84 MHz by 84: one count per µs.
//! - SPI1 (IMU): 84 MHz / 8 = 10.5 MHz, under the sensor's 24 MHz with
//!   margin for the wiring. SPI2 (card): 42 MHz / 128 = 328 kHz while the
//!   card is identified (at most 400 kHz), then 42 MHz / 2 = 21 MHz (at most
//!   25 MHz in default speed mode).
//! - A board with a 12 MHz crystal needs only M = 6 (and `HSE_HZ`).
//! - Without the crystal (it did not start within
//!   [`HSE_STARTUP_TIMEOUT_MS`]) the same tree runs from the 16 MHz HSI with
//!   M = 8: every frequency is the same, only less exact (±1 % at 25 °C,
//!   enough for the UART; recorded as a system fault).

use embassy_stm32::rcc::{
    AHBPrescaler, APBPrescaler, Hse, HseMode, Pll, PllMul, PllPDiv, PllPreDiv, PllQDiv, PllSource,
    Sysclk,
};
use embassy_stm32::time::Hertz;
use embassy_stm32::Config;

/// The crystal.
pub const HSE_HZ: u32 = 8_000_000;
/// Longest wait for the crystal to start (ST's reference value; a good
/// crystal needs about 2 ms).
pub const HSE_STARTUP_TIMEOUT_MS: u32 = 100;
/// SPI clock of the IMU (rounded down by the prescaler to 10.5 MHz).
pub const IMU_SPI_HZ: u32 = 10_500_000;
/// SPI clock of the card once identified.
pub const CARD_SPI_HZ: u32 = 21_000_000;

/// The chip configuration with the clock tree above, from the crystal if
/// `crystal` (it has started), else from the HSI.
pub fn config(crystal: bool) -> Config {
    let mut config = Config::default();
    let rcc = &mut config.rcc;
    let prediv = if crystal {
        rcc.hse = Some(Hse {
            freq: Hertz(HSE_HZ),
            mode: HseMode::Oscillator,
        });
        rcc.pll_src = PllSource::HSE;
        PllPreDiv::DIV4
    } else {
        rcc.hsi = true;
        rcc.pll_src = PllSource::HSI;
        PllPreDiv::DIV8
    };
    rcc.pll = Some(Pll {
        prediv,
        mul: PllMul::MUL168,
        divp: Some(PllPDiv::DIV2),
        divq: Some(PllQDiv::DIV7),
        divr: None,
    });
    rcc.sys = Sysclk::PLL1_P;
    rcc.ahb_pre = AHBPrescaler::DIV1;
    rcc.apb1_pre = APBPrescaler::DIV4;
    rcc.apb2_pre = APBPrescaler::DIV2;
    config
}
