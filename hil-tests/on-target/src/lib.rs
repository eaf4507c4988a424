//! What the on-target tests share: the board brought up as the logger
//! brings it up, and the loop-back wiring of the test bench.
//!
//! | from | to | for |
//! |---|---|---|
//! | PB6 (TIM4 CH1, PWM out) | PA0 (wheel input) | `wheel_capture` |
//! | PA2 (GPS TX) | PA3 (GPS RX) | `gps_uart` |
//! | PA9 (USART1 TX) to PA3, PA2 to PA10 (USART1 RX), instead of PA2-PA3 | a receiver played by USART1 | `gps_recovery` |
//! | PC0 (steering input) | the potentiometer, or any voltage between the rails | `adc_ring` |
//! | the IMU fitted | its INT1 on PA1 (the board's own wiring) | `imu_data_ready` |
//! | microSD socket | a FAT32 card | `sd_card`, `main_smoke` (with the IMU fitted) |
//! | microSD socket | exFAT, full FAT32 and FAT16 bench cards, as asked | `card_formats` |
//! | microSD socket | the card of the relay power cuts (bench step 5b), as asked | `power_cut` |
//! | none | | `sampler_cycles`, `stack_guard`, `debug_freeze`, `tim5_wrap` (its soak `#[ignore]`d: 75 min) |
//! | none (a bench supply at 3.3 V) | | `power_detector` |
//! | none | | `watchdog_reset`, `watchdog_stall` |
//!
//! The tests that ask the person at the bench for a card share its
//! adapter ([`sd_card`]) and their deadline loop ([`poll_until`]).
//!
//! Run them with a probe attached: `cargo test -p wobble-on-target --target
//! thumbv7em-none-eabihf` (the runner is probe-rs, see `firmware/docs/board.md`).
#![no_std]
#![warn(missing_docs)]

use embassy_futures::select::{select, Either};
use embassy_stm32::gpio::{Level, Output, Speed};
use embassy_stm32::peripherals::{IWDG, PB6, TIM4};
use embassy_stm32::spi::Spi;
use embassy_stm32::Peri;
use embassy_time::{Duration, Instant, Timer};
use wobble_core::app::sampler::FRAME_PERIOD_US;
use wobble_core::channels::SharedStatus;
use wobble_core::drivers::sdcard::IDENTIFICATION_CLOCK_HZ;
use wobble_core::format::{DecodeStats, Decoder, Event, BLOCK_LEN};
use wobble_stm32f405::adapters::card::{self, SdCard};
use wobble_stm32f405::pins::{Board, CardPins};
use wobble_stm32f405::{clocks, startup, watchdog};

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
    startup::freeze_timers_when_halted();
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

/// The card adapter on SPI2 at the identification clock, as the logger
/// builds it (`assembly::card_and_config` without `CONFIG.TXT`).
pub fn card_on(pins: CardPins) -> SdCard {
    let bus = Spi::new_blocking(
        pins.spi,
        pins.sck,
        pins.mosi,
        pins.miso,
        card::spi_config(IDENTIFICATION_CLOCK_HZ),
    );
    card::card(bus, Output::new(pins.cs, Level::High, Speed::VeryHigh))
}

/// The board brought up ([`board`]) and its card adapter ([`card_on`]).
pub fn sd_card() -> SdCard {
    let (board, _) = board();
    card_on(board.card)
}

/// Calls `poll` every `period` until it gives a value, for at most
/// `limit`: the value, or `None` at the deadline. The waits of the tests
/// that ask the person at the bench for something (a card inserted, pulled,
/// swapped).
pub async fn poll_until<T>(
    limit: Duration,
    period: Duration,
    mut poll: impl FnMut() -> Option<T>,
) -> Option<T> {
    let until = Instant::now() + limit;
    while Instant::now() < until {
        if let Some(value) = poll() {
            return Some(value);
        }
        Timer::after(period).await;
    }
    None
}

/// Runs the firmware's watchdog feeder (which starts the IWDG) for
/// `run_for` while both task heartbeats move, as the logger's tasks beat
/// them; returns with the watchdog running, to be fed no more.
pub async fn feed_watchdog_for(iwdg: Peri<'static, IWDG>, run_for: Duration) {
    // The feeder logs the queue's figures with the stack's once a minute.
    static SHARED: SharedStatus = SharedStatus::new();
    let queue = defmt::unwrap!(wobble_stm32f405::ccm::record_queue());
    let start = Instant::now();
    let heartbeats = async {
        while Instant::now() - start < run_for {
            watchdog::SAMPLER.beat();
            watchdog::GPS.beat();
            Timer::after_millis(10).await;
        }
    };
    match select(watchdog::feed(iwdg, queue, &SHARED), heartbeats).await {
        Either::First(never) => match never {},
        Either::Second(()) => {}
    }
}

/// The spacing of a log's frames as its reader meets them: how many, and
/// how many are not one frame period after the frame before.
#[derive(Default)]
pub struct FrameSpacing {
    /// Frames seen.
    pub frames: u32,
    /// Frames not [`FRAME_PERIOD_US`] after the one before.
    pub steps_off: u32,
    last_us: Option<u64>,
}

impl FrameSpacing {
    /// Takes the next frame's time, µs.
    pub fn see(&mut self, t_us: u64) {
        if self
            .last_us
            .is_some_and(|last| t_us != last + FRAME_PERIOD_US)
        {
            self.steps_off += 1;
        }
        self.last_us = Some(t_us);
        self.frames += 1;
    }
}

/// Decodes a log file on the card with the core's decoder, two blocks of
/// memory at a time, every event to `visit`; the decoder's totals.
pub fn decode_file<D, T, const DIRS: usize, const FILES: usize, const VOLUMES: usize>(
    file: &embedded_sdmmc::File<'_, D, T, DIRS, FILES, VOLUMES>,
    mut visit: impl FnMut(Event<'_>),
) -> DecodeStats
where
    D: embedded_sdmmc::BlockDevice,
    T: embedded_sdmmc::TimeSource,
{
    let mut decoder = Decoder::new();
    let mut buf = [0u8; 2 * BLOCK_LEN];
    let mut held = 0;
    loop {
        held += defmt::unwrap!(file.read(&mut buf[held..]).ok());
        let at_end = file.is_eof();
        let used = decoder.feed(&buf[..held], at_end, &mut |event| visit(event));
        buf.copy_within(used..held, 0);
        held -= used;
        if at_end {
            break;
        }
        defmt::assert!(held < buf.len(), "the decoder consumed nothing");
    }
    *decoder.stats()
}
