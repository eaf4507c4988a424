//! The wobble logger on an STM32F405RG board: brings up the clocks and the
//! peripherals of `pins.rs`, reads `CONFIG.TXT`, and hands everything to
//! the core's tasks.
//!
//! | executor | priority | tasks |
//! |---|---|---|
//! | interrupt (UART4 vector) | high | 100 Hz sampler |
//! | interrupt (UART5 vector) | medium | GPS |
//! | thread mode | low | SD writer (blocking), watchdog feeder |
#![no_std]
#![no_main]

use wobble_stm32f405::{adapters, clocks, pins, startup, watchdog};

use cortex_m_rt::entry;
use embassy_executor::{Executor, InterruptExecutor};
use embassy_stm32::adc::{Adc, AdcChannel, Exten, RingBufferedAdc, SampleTime, CONTINUOUS};
use embassy_stm32::gpio::{Input, Level, Output, Pull, Speed};
use embassy_stm32::interrupt;
use embassy_stm32::interrupt::{InterruptExt, Priority};
use embassy_stm32::peripherals::{ADC1, IWDG};
use embassy_stm32::spi::Spi;
use embassy_stm32::Peri;
use embassy_time::Instant;
use static_cell::StaticCell;
use wobble_core::app::sampler::{Sampler, SamplerPorts};
use wobble_core::app::{gps, sampler, writer};
use wobble_core::boot;
use wobble_core::channels::{RecordQueue, SharedStatus};
use wobble_core::config::{self, Config, Loaded, KEY_COUNT, MAX_TEXT_LEN};
use wobble_core::format::Record;
use wobble_core::frame_assembly::FrameConfig;
use wobble_core::logger::{CardLogger, FixedTime, HeaderSpec, LoggerConfig, Volumes};
use wobble_core::steering::Steering;
use wobble_core::wheel::WheelSpeed;
use {defmt_rtt as _, panic_probe as _};

use wobble_stm32f405::adapters::card::SdCard;
use wobble_stm32f405::adapters::gps::GpsAdapter;
use wobble_stm32f405::adapters::imu::ImuAdapter;
use wobble_stm32f405::adapters::rider::{AlertPins, MarkerButton, StatusLight};
use wobble_stm32f405::adapters::steering::SteeringAdapter;
use wobble_stm32f405::adapters::wheel::WheelAdapter;
use wobble_stm32f405::pins::{Board, Irqs};

/// Records from the sampler and the GPS task to the SD writer.
static QUEUE: RecordQueue = RecordQueue::new();
/// Fix age and card state, shared by the tasks.
static SHARED: SharedStatus = SharedStatus::new();

static EXECUTOR_HIGH: InterruptExecutor = InterruptExecutor::new();
static EXECUTOR_MEDIUM: InterruptExecutor = InterruptExecutor::new();
static EXECUTOR_THREAD: StaticCell<Executor> = StaticCell::new();

/// The configuration in force as text, and its lines for the log header.
static CONFIG_TEXT: StaticCell<heapless::String<MAX_TEXT_LEN>> = StaticCell::new();
static CONFIG_LINES: StaticCell<heapless::Vec<&'static str, KEY_COUNT>> = StaticCell::new();

const FIRMWARE: &str = concat!(env!("CARGO_PKG_NAME"), " ", env!("CARGO_PKG_VERSION"));
/// 100 Hz, from the sampler's period.
const FRAME_RATE_HZ: u16 = (1_000_000 / sampler::FRAME_PERIOD_US) as u16;
/// Room for `CONFIG.TXT` (on the stack, at boot only): about 100 lines.
const CONFIG_FILE_BYTES: usize = 4096;

type Ports =
    SamplerPorts<ImuAdapter, SteeringAdapter, WheelAdapter, MarkerButton, AlertPins, StatusLight>;

#[interrupt]
unsafe fn UART4() {
    // SAFETY: the vector belongs to this executor alone (UART4 is unused).
    unsafe { EXECUTOR_HIGH.on_interrupt() }
}

#[interrupt]
unsafe fn UART5() {
    // SAFETY: the vector belongs to this executor alone (UART5 is unused).
    unsafe { EXECUTOR_MEDIUM.on_interrupt() }
}

#[entry]
fn main() -> ! {
    startup::guard_stack();
    // RTT needs no clock: this line appears even if the clocks never come up.
    defmt::info!("{} starting", FIRMWARE);
    let reset = startup::take_reset_cause();
    defmt::info!("reset cause: {}", reset);
    let streak = startup::take_panic_streak(reset);
    let crystal = startup::start_hse();
    if !crystal {
        defmt::error!(
            "HSE did not start in {} ms: running on HSI",
            clocks::HSE_STARTUP_TIMEOUT_MS
        );
    }
    let mut board = Board::new(embassy_stm32::init(clocks::config(crystal)));
    startup::enable_flash_accelerator();
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
        (!crystal).then_some(boot::FAULT_HSE_FAILED),
        bor,
    ];
    for code in boot_faults.into_iter().flatten() {
        QUEUE.push(Record::Fault(boot::system_fault(code, 0)));
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
            "{} software resets in a row: not logging until power-off",
            streak
        );
        let mut led = Output::new(board.rider.alert_led.reborrow(), Level::Low, Speed::Low);
        loop {
            startup::blink_code(&mut led, boot::FAULT_RESET_SOFTWARE);
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
            thread.spawn(defmt::unwrap!(selftest_task(parts)));
        })
    }
    let t_us = Instant::now().as_micros();
    for fault in loaded.faults.records(t_us) {
        QUEUE.push(Record::Fault(fault));
    }
    let logger = CardLogger::new(
        card,
        FixedTime::EPOCH,
        header(&config),
        LoggerConfig::DEFAULT,
    );

    let _wheel_timer = adapters::wheel::start(board.wheel);
    let (sampler, ports) = sampler_parts(board.imu, board.steering, board.rider, &config);
    let gps_port = GpsAdapter::new(board.gps);

    interrupt::UART4.set_priority(Priority::P6);
    let high = EXECUTOR_HIGH.start(interrupt::UART4);
    high.spawn(defmt::unwrap!(sampler_task(sampler, ports)));

    interrupt::UART5.set_priority(Priority::P7);
    let medium = EXECUTOR_MEDIUM.start(interrupt::UART5);
    medium.spawn(defmt::unwrap!(gps_task(gps_port)));

    let watchdog = board.watchdog;
    EXECUTOR_THREAD.init(Executor::new()).run(move |thread| {
        thread.spawn(defmt::unwrap!(writer_task(logger)));
        thread.spawn(defmt::unwrap!(watchdog_task(watchdog)));
    })
}

/// Whether the marker button is held at power-on: the rider asks for the
/// field self-test instead of a ride.
fn marker_held(board: &mut Board) -> bool {
    let button = Input::new(board.rider.marker.reborrow(), Pull::Up);
    // Let the pull-up charge the line before reading it.
    embassy_time::block_for(embassy_time::Duration::from_millis(20));
    button.is_low()
}

/// Opens the card and reads `CONFIG.TXT` (defaults without a card).
fn card_and_config(pins: pins::CardPins) -> (SdCard, Loaded) {
    let bus = Spi::new_blocking(
        pins.spi,
        pins.sck,
        pins.mosi,
        pins.miso,
        adapters::card::spi_config(wobble_core::drivers::sdcard::IDENTIFICATION_CLOCK_HZ),
    );
    let cs = Output::new(pins.cs, Level::High, Speed::VeryHigh);
    let volumes = Volumes::new_with_limits(adapters::card::card(bus, cs), FixedTime::EPOCH, 0);
    let mut file = [0u8; CONFIG_FILE_BYTES];
    let (loaded, source) = config::load(&volumes, &mut file);
    defmt::info!("config: {}, {} faults", source, loaded.faults.first().len());
    for fault in loaded.faults.first() {
        defmt::warn!("CONFIG.TXT line {}: fault {}", fault.line, fault.code);
    }
    let (card, _) = volumes.free();
    (card, loaded)
}

/// The header of every log file: identity and the configuration in force.
fn header(config: &Config) -> HeaderSpec<'static> {
    let text = CONFIG_TEXT.init(heapless::String::new());
    if config.write_lines(text).is_err() {
        defmt::warn!("config text cut at {} bytes", MAX_TEXT_LEN);
    }
    let text: &'static heapless::String<MAX_TEXT_LEN> = text;
    let lines = CONFIG_LINES.init(text.lines().take(KEY_COUNT).collect());
    HeaderSpec {
        firmware: FIRMWARE,
        device_id: embassy_stm32::uid::uid(),
        sample_rate_hz: FRAME_RATE_HZ,
        config: lines,
    }
}

/// The sensors, rider I/O and the sampler's state.
fn sampler_parts(
    imu: pins::ImuPins,
    steering: pins::SteeringPins,
    rider: pins::RiderPins,
    config: &Config,
) -> (Sampler, Ports) {
    let imu = adapters::imu::port(imu, config.imu);

    let steering = SteeringAdapter::new(
        steering_adc(steering.adc, steering.wiper, steering.dma),
        defmt::unwrap!(Steering::try_new(config.steering).ok()),
    );

    let ports = SamplerPorts {
        imu,
        steering,
        wheel: WheelAdapter::default(),
        marker: MarkerButton(Input::new(rider.marker, Pull::Up)),
        alert: AlertPins {
            buzzer: Output::new(rider.buzzer, Level::Low, Speed::Low),
            led: Output::new(rider.alert_led, Level::Low, Speed::Low),
            enabled: config.alert.enabled,
        },
        status_led: StatusLight {
            led: Output::new(rider.status_led, Level::Low, Speed::Low),
            frames: 0,
        },
    };
    let sampler = Sampler::new(
        defmt::unwrap!(WheelSpeed::try_new(config.wheel).ok()),
        FrameConfig::DEFAULT,
        defmt::unwrap!(config.detector().ok()),
        config.alert,
    );
    (sampler, ports)
}

/// ADC1 converting the wiper continuously into a DMA ring, the slowest
/// sample time (480 cycles) for the pot's source impedance.
fn steering_adc(
    adc: Peri<'static, ADC1>,
    wiper: Peri<'static, embassy_stm32::peripherals::PC0>,
    dma: Peri<'static, embassy_stm32::peripherals::DMA2_CH4>,
) -> RingBufferedAdc<'static, ADC1> {
    Adc::new(adc).into_ring_buffered(
        dma,
        adapters::steering::ring(),
        Irqs,
        [(wiper.degrade_adc(), SampleTime::CYCLES480)].into_iter(),
        CONTINUOUS,
        Exten::DISABLED,
    )
}

#[embassy_executor::task]
async fn sampler_task(mut sampler: Sampler, mut ports: Ports) {
    ports.imu.start().await;
    sampler::run(
        &mut sampler,
        &mut ports,
        &QUEUE,
        &SHARED,
        u32::MAX,
        &mut |t_us, event| {
            defmt::info!("alert at {} us: {}", t_us, event);
        },
    )
    .await;
}

#[embassy_executor::task]
async fn gps_task(mut port: GpsAdapter) {
    gps::run_link(&mut port, &QUEUE, &SHARED, &mut |step| {
        defmt::info!("GPS set-up: {}", step);
    })
    .await;
}

#[embassy_executor::task]
async fn selftest_task(parts: wobble_stm32f405::selftest::Parts) {
    wobble_stm32f405::selftest::run(parts).await
}

#[embassy_executor::task]
async fn writer_task(mut logger: CardLogger<'static, SdCard, FixedTime>) {
    if let Err(e) = writer::run(&mut logger, &QUEUE, &SHARED).await {
        defmt::error!("log not closed cleanly: {}", e);
    }
}

#[embassy_executor::task]
async fn watchdog_task(iwdg: Peri<'static, IWDG>) {
    watchdog::feed(iwdg).await
}
