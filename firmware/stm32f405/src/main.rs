//! The wobble logger on an STM32F405RG board: brings up the clocks and the
//! peripherals of `pins.rs`, reads `CONFIG.TXT` (both through the library's
//! `assembly`, which on-target tests can call too), and hands everything to
//! the core's tasks.
//!
//! | executor | priority | tasks |
//! |---|---|---|
//! | interrupt (UART4 vector) | high | 100 Hz sampler |
//! | interrupt (UART5 vector) | medium | GPS |
//! | interrupt (PVD vector) | low | supply below 2.9 V (a flag for the writer) |
//! | thread mode | low | SD writer (blocking), watchdog feeder |
#![no_std]
#![no_main]

use wobble_stm32f405::assembly::{
    card_and_config, header, marker_held, sampler_parts, Ports, FIRMWARE,
};
use wobble_stm32f405::{adapters, ccm, clocks, power, startup, watchdog};

use cortex_m_rt::entry;
use embassy_executor::{Executor, InterruptExecutor};
use embassy_stm32::gpio::{Level, Output, Speed};
use embassy_stm32::interrupt;
use embassy_stm32::interrupt::{InterruptExt, Priority};
use embassy_stm32::peripherals::IWDG;
use embassy_stm32::Peri;
use embassy_time::Instant;
use static_cell::StaticCell;
use wobble_core::app::sampler::Sampler;
use wobble_core::app::{gps, sampler, writer};
use wobble_core::boot;
use wobble_core::channels::{RecordQueue, SharedStatus};
use wobble_core::config;
use wobble_core::format::Record;
use wobble_core::logger::{CardLogger, GpsTime, LoggerConfig};
use {defmt_rtt as _, panic_probe as _};

use wobble_stm32f405::adapters::card::SdCard;
use wobble_stm32f405::adapters::gps::GpsAdapter;
use wobble_stm32f405::pins::Board;

/// Fix age and card state, shared by the tasks.
static SHARED: SharedStatus = SharedStatus::new();

static EXECUTOR_HIGH: InterruptExecutor = InterruptExecutor::new();
static EXECUTOR_MEDIUM: InterruptExecutor = InterruptExecutor::new();
static EXECUTOR_THREAD: StaticCell<Executor> = StaticCell::new();

#[interrupt]
unsafe fn UART4() {
    // SAFETY: the vector belongs to this executor alone (UART4 is unused).
    unsafe { EXECUTOR_HIGH.on_interrupt() }
}

#[interrupt]
fn PVD() {
    power::on_interrupt(&SHARED);
}

#[interrupt]
unsafe fn UART5() {
    // SAFETY: the vector belongs to this executor alone (UART5 is unused).
    unsafe { EXECUTOR_MEDIUM.on_interrupt() }
}

#[entry]
fn main() -> ! {
    startup::guard_stack();
    // Records from the sampler and the GPS task to the SD writer, in CCM.
    let queue = defmt::unwrap!(ccm::record_queue());
    // RTT needs no clock: this line appears even if the clocks never come up.
    defmt::info!("{} starting", FIRMWARE);
    let reset = startup::take_reset_cause();
    defmt::info!("reset cause: {}", reset);
    let (streak, crystal_failed) = startup::take_panic_streak(reset);
    if crystal_failed {
        defmt::error!("crystal failed during the last run (clock security system): reset");
    }
    let crystal = startup::start_hse();
    if !crystal {
        defmt::error!(
            "HSE did not start in {} ms: running on HSI",
            clocks::HSE_STARTUP_TIMEOUT_MS
        );
    }
    let mut board = Board::new(embassy_stm32::init(clocks::config(crystal)));
    startup::enable_flash_accelerator();
    // A debugger's halt stops the time base, the capture timer and the
    // watchdog together.
    startup::freeze_timers_when_halted();
    // The writer closes the log when VDD falls below 2.9 V, and opens no
    // file before it is above.
    power::start(&SHARED);
    if crystal {
        startup::enable_clock_security();
    }
    let bor = boot::bor_fault(startup::bor_level());
    if let Some(code) = bor {
        defmt::warn!(
            "brown-out reset below 2.7 V (system fault {}): run the self-test to program it",
            code
        );
    }
    let boot_faults = [
        Some(reset.fault_code()),
        boot::crystal_fault(crystal, crystal_failed),
        bor,
    ];
    for code in boot_faults.into_iter().flatten() {
        queue.push(Record::Fault(boot::system_fault(code, 0)));
    }
    let debugger = cortex_m::peripheral::DCB::is_debugger_attached();
    if reset.blink_at_boot(debugger) || !crystal {
        // Shown on the alert LED before logging starts: the cause, or 9
        // for the crystal.
        let code = if crystal {
            reset.fault_code()
        } else {
            boot::FAULT_HSE_FAILED
        };
        let mut led = Output::new(board.rider.alert_led.reborrow(), Level::Low, Speed::Low);
        startup::blink_code(&mut led, code);
    }

    if boot::in_panic_loop(streak) {
        // Nothing is written: no new log file per boot. The code repeats
        // until a power cycle (the watchdog is not started).
        defmt::error!(
            "{} panic, fault or watchdog resets in a row: not logging until power-off",
            streak
        );
        let mut led = Output::new(board.rider.alert_led.reborrow(), Level::Low, Speed::Low);
        loop {
            // 5 after a panic or a fault, 3 after a hang.
            startup::blink_code(&mut led, reset.fault_code());
        }
    }
    let button = marker_held(&mut board);
    let (card, loaded) = card_and_config(board.card);
    let config = loaded.config;
    if button || loaded.selftest {
        if loaded.selftest {
            defmt::info!(
                "{}: selftest=1 (remove the line to ride)",
                config::FILE_NAME
            );
        }
        let _wheel_timer = adapters::wheel::start(board.wheel);
        let (_, ports) = sampler_parts(board.imu, board.steering, board.rider, &config);
        let parts = wobble_stm32f405::selftest::Parts {
            imu: ports.imu,
            steering: ports.steering,
            wheel: ports.wheel,
            gps: GpsAdapter::new(board.gps),
            card,
            buzzer: ports.alert.buzzer,
            alert_led: ports.alert.led,
            status_led: ports.status_led.led,
            crystal,
            reset,
        };
        EXECUTOR_THREAD.init(Executor::new()).run(move |thread| {
            thread.spawn(defmt::unwrap!(selftest_task(parts, queue)));
        })
    }
    let t_us = Instant::now().as_micros();
    for fault in loaded.faults.records(t_us) {
        queue.push(Record::Fault(fault));
    }
    // Files dated from the GPS's UTC once it is known (2020-01-01 before).
    let logger = CardLogger::new(
        card,
        GpsTime::new(&SHARED, || Instant::now().as_micros()),
        header(&config),
        LoggerConfig::DEFAULT,
    );

    let _wheel_timer = adapters::wheel::start(board.wheel);
    let (sampler, ports) = sampler_parts(board.imu, board.steering, board.rider, &config);
    let gps_port = GpsAdapter::new(board.gps);

    interrupt::UART4.set_priority(Priority::P6);
    let high = EXECUTOR_HIGH.start(interrupt::UART4);
    high.spawn(defmt::unwrap!(sampler_task(sampler, ports, queue)));

    interrupt::UART5.set_priority(Priority::P7);
    let medium = EXECUTOR_MEDIUM.start(interrupt::UART5);
    medium.spawn(defmt::unwrap!(gps_task(gps_port, queue)));

    let watchdog = board.watchdog;
    EXECUTOR_THREAD.init(Executor::new()).run(move |thread| {
        thread.spawn(defmt::unwrap!(writer_task(logger, queue)));
        thread.spawn(defmt::unwrap!(watchdog_task(watchdog, queue)));
    })
}

#[embassy_executor::task]
async fn sampler_task(mut sampler: Sampler, mut ports: Ports, queue: &'static RecordQueue) {
    ports.imu.start().await;
    sampler::run(
        &mut sampler,
        &mut ports,
        queue,
        &SHARED,
        u32::MAX,
        &mut |t_us, event| {
            defmt::info!("alert at {} us: {}", t_us, event);
        },
    )
    .await;
}

#[embassy_executor::task]
async fn gps_task(mut port: GpsAdapter, queue: &'static RecordQueue) {
    gps::run_link(&mut port, queue, &SHARED, &mut |step| {
        defmt::info!("GPS set-up: {}", step);
    })
    .await;
}

#[embassy_executor::task]
async fn selftest_task(parts: wobble_stm32f405::selftest::Parts, queue: &'static RecordQueue) {
    wobble_stm32f405::selftest::run(parts, queue).await
}

#[embassy_executor::task]
async fn writer_task(
    mut logger: CardLogger<'static, SdCard, GpsTime<'static>>,
    queue: &'static RecordQueue,
) {
    if let Err(e) = writer::run(&mut logger, queue, &SHARED).await {
        defmt::error!("log not closed cleanly: {}", e);
    }
}

#[embassy_executor::task]
async fn watchdog_task(iwdg: Peri<'static, IWDG>, queue: &'static RecordQueue) {
    watchdog::feed(iwdg, queue, &SHARED).await
}
