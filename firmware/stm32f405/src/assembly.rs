//! Main's assembly: the peripherals of `pins.rs` built into the core's
//! tasks' parts (the card and `CONFIG.TXT`, the log header, the sampler's
//! ports), shared by the logger binary (`src/main.rs`, which owns the
//! executors and tasks) and the on-target tests.

use embassy_stm32::adc::{Adc, AdcChannel, Exten, RingBufferedAdc, SampleTime, CONTINUOUS};
use embassy_stm32::gpio::{Input, Level, Output, Pull, Speed};
use embassy_stm32::peripherals::ADC1;
use embassy_stm32::spi::Spi;
use embassy_stm32::Peri;
use static_cell::StaticCell;
use wobble_core::app::sampler::{self, Sampler, SamplerPorts};
use wobble_core::config::{self, Config, Loaded, KEY_COUNT, MAX_TEXT_LEN};
use wobble_core::frame_assembly::FrameConfig;
use wobble_core::logger::{self, FixedTime, HeaderSpec};
use wobble_core::steering::Steering;
use wobble_core::wheel::WheelSpeed;

use crate::adapters;
use crate::adapters::card::SdCard;
use crate::adapters::imu::ImuAdapter;
use crate::adapters::rider::{AlertPins, MarkerButton, StatusLight};
use crate::adapters::steering::SteeringAdapter;
use crate::adapters::wheel::WheelAdapter;
use crate::pins::{self, Board, Irqs};

/// The configuration in force as text, and its lines for the log header.
static CONFIG_TEXT: StaticCell<heapless::String<MAX_TEXT_LEN>> = StaticCell::new();
static CONFIG_LINES: StaticCell<heapless::Vec<&'static str, KEY_COUNT>> = StaticCell::new();

/// The firmware's name and version, as the log header carries them.
pub const FIRMWARE: &str = concat!(env!("CARGO_PKG_NAME"), " ", env!("CARGO_PKG_VERSION"));
/// 100 Hz, from the sampler's period.
const FRAME_RATE_HZ: u16 = (1_000_000 / sampler::FRAME_PERIOD_US) as u16;
/// Room for `CONFIG.TXT` (on the stack, at boot only): about 100 lines.
const CONFIG_FILE_BYTES: usize = 4096;

/// The sampler's ports on this board.
pub type Ports =
    SamplerPorts<ImuAdapter, SteeringAdapter, WheelAdapter, MarkerButton, AlertPins, StatusLight>;

/// Whether the marker button is held at power-on: the rider asks for the
/// field self-test instead of a ride.
pub fn marker_held(board: &mut Board) -> bool {
    let button = Input::new(board.rider.marker.reborrow(), Pull::Up);
    // Let the pull-up charge the line before reading it.
    embassy_time::block_for(embassy_time::Duration::from_millis(20));
    button.is_low()
}

/// Opens the card and reads `CONFIG.TXT` (defaults without a card).
pub fn card_and_config(pins: pins::CardPins) -> (SdCard, Loaded) {
    let bus = Spi::new_blocking(
        pins.spi,
        pins.sck,
        pins.mosi,
        pins.miso,
        adapters::card::spi_config(wobble_core::drivers::sdcard::IDENTIFICATION_CLOCK_HZ),
    );
    let cs = Output::new(pins.cs, Level::High, Speed::VeryHigh);
    let volumes = logger::volumes(adapters::card::card(bus, cs), FixedTime::EPOCH);
    let mut file = [0u8; CONFIG_FILE_BYTES];
    let (loaded, source) = config::load(&volumes, &mut file);
    defmt::info!("config: {}, {} faults", source, loaded.faults.first().len());
    for fault in loaded.faults.first() {
        defmt::warn!("CONFIG.TXT line {}: fault {}", fault.line, fault.code);
    }
    let (card, _) = volumes.free();
    (card.into_inner(), loaded)
}

/// The header of every log file: identity and the configuration in force.
pub fn header(config: &Config) -> HeaderSpec<'static> {
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
pub fn sampler_parts(
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
