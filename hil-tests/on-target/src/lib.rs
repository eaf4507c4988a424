//! What the on-target tests share: the board brought up as the logger
//! brings it up, and the loop-back wiring of the test bench.
//!
//! | from | to | for |
//! |---|---|---|
//! | PB6 (TIM4 CH1, PWM out) | PA0 (wheel input) | `wheel_capture` |
//! | PA2 (GPS TX) | PA3 (GPS RX) | `gps_uart` |
//! | PA9 (USART1 TX) to PA3, PA2 to PA10 (USART1 RX), instead of PA2-PA3 | a receiver played by USART1 | `gps_recovery` |
//! | PC0 (steering input) | the potentiometer, or any voltage between the rails | `adc_ring` |
//! | microSD socket | a FAT32 card | `sd_card`, `main_smoke` (with the IMU fitted) |
//! | microSD socket | exFAT, full FAT32 and FAT16 bench cards, as asked | `card_formats` |
//! | none | | `sampler_cycles` |
//!
//! Run them with a probe attached: `cargo test -p wobble-on-target --target
//! thumbv7em-none-eabihf` (the runner is probe-rs, see `firmware/docs/board.md`).
#![no_std]
#![warn(missing_docs)]

use embassy_stm32::peripherals::{PB6, TIM4};
use embassy_stm32::Peri;
use wobble_stm32f405::pins::Board;
use wobble_stm32f405::{clocks, startup};

/// The pins of the PWM loop-back source, outside the logger's pin map.
pub struct PwmSource {
    /// TIM4, free in the logger.
    pub timer: Peri<'static, TIM4>,
    /// PB6: TIM4 CH1, wired to PA0.
    pub pin: Peri<'static, PB6>,
}

/// Brings the chip up exactly as the logger does (crystal with its
/// time-out, clock tree, flash accelerator) and hands out the board.
pub fn board() -> (Board, PwmSource) {
    let crystal = startup::start_hse();
    let p = embassy_stm32::init(clocks::config(crystal));
    startup::enable_flash_accelerator();
    defmt::info!(
        "clocks from the {}",
        if crystal { "crystal" } else { "HSI" }
    );
    // SAFETY: TIM4 and PB6 are in no role of the board's pin map, so
    // nothing else owns them.
    let pwm = unsafe {
        PwmSource {
            timer: TIM4::steal(),
            pin: PB6::steal(),
        }
    };
    (Board::new(p), pwm)
}
