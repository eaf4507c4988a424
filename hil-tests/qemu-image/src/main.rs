//! The logger's core tasks on QEMU's `netduinoplus2` (STM32F405): the same
//! sampler, GPS and writer tasks as the board, in the board's executor
//! layout (sampler high, GPS medium, writer in thread mode), reading
//! `CONFIG.TXT` from the card as the board does, with raw sensor values
//! replayed through the core's IMU driver and channels and a semihosted
//! FAT32 card image with SD timing. Reports to the harness on
//! semihosting stdout; QEMU's exit code is the run's outcome (0 done,
//! 2 bad scenario, 3 power cut).
#![no_std]
#![no_main]

mod card;
mod executor;
mod imu_bus;
mod replay;
mod report;
mod scenario;
mod sd_timing;
mod time_driver;

use core::cell::RefCell;
use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m_rt::entry;
use embassy_time::{Delay, Instant};
use embedded_sdmmc::VolumeManager;
use static_cell::StaticCell;
use wobble_core::app::imu_port::Icm42688Port;
use wobble_core::app::ports::{AlertOutput, LoggerHealth, StatusLed};
use wobble_core::app::sampler::{Sampler, SamplerPorts};
use wobble_core::app::{gps, sampler, writer};
use wobble_core::channels::{RecordQueue, SharedStatus};
use wobble_core::config::{self, Config, Loaded, KEY_COUNT, MAX_TEXT_LEN};
use wobble_core::drivers::icm42688::{self, Icm42688};
use wobble_core::format::Record;
use wobble_core::frame_assembly::FrameConfig;
use wobble_core::gps::{GpsConfig, GpsReceiver};
use wobble_core::imu::Imu;
use wobble_core::logger::{
    CardLogger, FixedTime, HeaderSpec, LoggerConfig, FAULT_CARD_ABSENT, FAULT_CARD_FULL,
    FAULT_CARD_WRITE,
};
use wobble_core::steering::Steering;
use wobble_core::wheel::WheelSpeed;

use crate::card::SemihostingCard;
use crate::imu_bus::EmulatedIcm42688;
use crate::replay::{Gps, Port, ReplayedAdc, Ride};
use crate::scenario::Scenario;

/// Frames the sampler has taken (for the power-cut report).
pub static FRAMES_SAMPLED: AtomicU32 = AtomicU32::new(0);
static QUEUE: RecordQueue = RecordQueue::new();
static SHARED: SharedStatus = SharedStatus::new();
static MAX_LATE_US: AtomicU32 = AtomicU32::new(0);

/// NVIC priorities (4 bits on the STM32F4, upper nibble; lower value wins):
/// the time driver above the sampler, the sampler above the GPS task, the
/// GPS task above thread mode (the board: P6 and P7 for sampler and GPS).
const SYSTICK_PRIORITY: u8 = 0x40;
const SAMPLER_PRIORITY: u8 = 0x80;
const GPS_PRIORITY: u8 = 0xC0;
/// Room for `CONFIG.TXT`, as on the board.
const CONFIG_FILE_BYTES: usize = 4096;

/// The IMU port: the board's, on the emulated sensor.
type ImuPort = Icm42688Port<EmulatedIcm42688, Delay>;

/// The configuration's `key=value` lines for the log header, as the board
/// writes them.
fn config_lines(config: &Config) -> &'static [&'static str] {
    static TEXT: StaticCell<heapless::String<MAX_TEXT_LEN>> = StaticCell::new();
    static LINES: StaticCell<heapless::Vec<&'static str, KEY_COUNT>> = StaticCell::new();
    let text = TEXT.init(heapless::String::new());
    if config.write_lines(text).is_err() {
        report::line(format_args!("FATAL configuration text too long"));
        semihosting::process::exit(2)
    }
    let text: &'static heapless::String<MAX_TEXT_LEN> = text;
    LINES.init(text.lines().take(KEY_COUNT).collect())
}

/// The buzzer and the alert LED: the harness hears the alert through the
/// `ALERT` lines instead.
struct QuietAlert;

impl AlertOutput for QuietAlert {
    fn set_buzzer(&mut self, _on: bool) {}
    fn set_led(&mut self, _on: bool) {}
}

/// The status LED, reported on change.
struct StatusLine(Option<LoggerHealth>);

impl StatusLed for StatusLine {
    fn show(&mut self, health: LoggerHealth) {
        if self.0 != Some(health) {
            self.0 = Some(health);
            report::line(format_args!(
                "STATUS {health:?} t_us={}",
                Instant::now().as_micros()
            ));
        }
    }
}

/// Stops the run: a configuration `Config::parse` let through was refused.
fn rejected() -> ! {
    report::line(format_args!("FATAL configuration rejected"));
    semihosting::process::exit(2)
}

#[embassy_executor::task]
async fn sampler_task(
    ride: &'static RefCell<Ride>,
    scenario: &'static Scenario,
    config: &'static Config,
) {
    let (Ok(wheel), Ok(detector)) = (WheelSpeed::try_new(config.wheel), config.detector()) else {
        rejected()
    };
    let driver_config = icm42688::Config::default();
    let (Ok(imu), Ok(steering)) = (
        Imu::try_new(driver_config.imu_config(config.imu)),
        Steering::try_new(config.steering),
    ) else {
        rejected()
    };
    let bus = EmulatedIcm42688::new(ride, scenario);
    let mut imu: ImuPort = Icm42688Port::new(Icm42688::new(bus, driver_config), imu, Delay);
    imu.start().await;
    let mut s = Sampler::new(wheel, FrameConfig::DEFAULT, detector, config.alert);
    let mut ports = SamplerPorts {
        imu,
        steering: ReplayedAdc::new(ride, steering, scenario),
        wheel: Port(ride),
        marker: Port(ride),
        alert: QuietAlert,
        status_led: StatusLine(None),
    };
    // Frame k (from 1) is due at this time + k x 10 ms.
    report::line(format_args!("START t_us={}", Instant::now().as_micros()));
    sampler::run(
        &mut s,
        &mut ports,
        &QUEUE,
        &SHARED,
        scenario.frames,
        &mut report::alert,
    )
    .await;
    MAX_LATE_US.store(s.stats().max_lateness_us, Ordering::Relaxed);
    SHARED.request_stop();
}

#[embassy_executor::task]
async fn gps_task(scenario: &'static Scenario) {
    let mut port = Gps::open(scenario);
    let mut receiver = GpsReceiver::new(GpsConfig::default());
    gps::run(&mut port, &mut receiver, &QUEUE, &SHARED).await;
}

#[embassy_executor::task]
async fn writer_task(card: SemihostingCard, config: &'static Config) {
    let header = HeaderSpec {
        firmware: concat!("wobble-qemu-image ", env!("CARGO_PKG_VERSION")),
        device_id: *b"QEMU-NETDUI2",
        sample_rate_hz: 100,
        config: config_lines(config),
    };
    let mut logger = CardLogger::new(card, FixedTime::EPOCH, header, LoggerConfig::DEFAULT);
    let closed = writer::run(&mut logger, &QUEUE, &SHARED).await;
    let st = logger.stats();
    report::line(format_args!(
        "END frames={} t_us={} max_late_us={} queue_high_water={} queue_frames_dropped={} \
         queue_others_dropped={} card_frames_lost={} card_absent={} card_write_failed={} card_full={} files={} closed={}",
        FRAMES_SAMPLED.load(Ordering::Relaxed),
        Instant::now().as_micros(),
        MAX_LATE_US.load(Ordering::Relaxed),
        QUEUE.high_water(),
        QUEUE.frames_dropped_pending(),
        QUEUE.others_dropped(),
        st.frames_lost,
        st.faults[usize::from(FAULT_CARD_ABSENT - 1)],
        st.faults[usize::from(FAULT_CARD_WRITE - 1)],
        st.faults[usize::from(FAULT_CARD_FULL - 1)],
        st.files_opened,
        closed.is_ok(),
    ));
    semihosting::process::exit(0)
}

fn load_scenario() -> &'static Scenario {
    static TEXT: StaticCell<[u8; 1024]> = StaticCell::new();
    static SCENARIO: StaticCell<Scenario> = StaticCell::new();
    let text = TEXT.init([0; 1024]);
    let n = semihosting::fs::File::open(c"scenario.txt")
        .and_then(|mut f| semihosting::io::Read::read(&mut f, text))
        .unwrap_or(0);
    match core::str::from_utf8(&text[..n]).map(Scenario::parse) {
        Ok(Ok(s)) if s.frames > 0 => SCENARIO.init(s),
        Ok(Err(line)) => {
            report::line(format_args!("FATAL scenario line not understood: {line}"));
            semihosting::process::exit(2)
        }
        _ => {
            report::line(format_args!(
                "FATAL scenario.txt missing, not UTF-8 or no frames"
            ));
            semihosting::process::exit(2)
        }
    }
}

/// Opens the card and reads `CONFIG.TXT` (defaults without a card), as the
/// board does.
fn card_and_config(scenario: &'static Scenario) -> (SemihostingCard, Loaded) {
    let volumes = VolumeManager::new(SemihostingCard::open(scenario), FixedTime::EPOCH);
    let mut file = [0u8; CONFIG_FILE_BYTES];
    let (loaded, source) = config::load(&volumes, &mut file);
    report::line(format_args!(
        "CONFIG source={source:?} faults={}",
        loaded.faults.first().len()
    ));
    let (card, _) = volumes.free();
    (card, loaded)
}

/// Most steering samples the detector benchmark holds.
const BENCH_SAMPLES: usize = 3000;

/// Times the wobble detector alone over the ride's steering at 4 m/s:
/// `BENCH detector samples=N us=T`, virtual time, which the harness turns
/// into instructions. The samples are read first, so no file access is
/// timed.
fn bench_detector(ride: &mut Ride, config: &Config) -> ! {
    static SAMPLES: StaticCell<heapless::Vec<f32, BENCH_SAMPLES>> = StaticCell::new();
    let samples = SAMPLES.init(heapless::Vec::new());
    let (Ok(mut steering), Ok(mut detector)) =
        (Steering::try_new(config.steering), config.detector())
    else {
        rejected()
    };
    while let Some(deg) = ride.next_steer_deg(&mut steering) {
        if samples.push(deg).is_err() {
            break;
        }
    }
    let start = Instant::now();
    let alerts = samples
        .iter()
        .filter(|&&deg| detector.push(deg, Some(4.0)).is_some())
        .count();
    let us = Instant::now().as_micros() - start.as_micros();
    report::line(format_args!(
        "BENCH detector samples={} us={us} alert_changes={alerts}",
        samples.len()
    ));
    semihosting::process::exit(0)
}

#[entry]
fn main() -> ! {
    let Some(mut cp) = cortex_m::Peripherals::take() else {
        semihosting::process::exit(2)
    };
    let scenario = load_scenario();
    static RIDE: StaticCell<RefCell<Ride>> = StaticCell::new();
    static CONFIG: StaticCell<Config> = StaticCell::new();
    let ride: &'static RefCell<Ride> = RIDE.init(RefCell::new(Ride::open()));
    time_driver::init(cp.SYST, &mut cp.SCB, SYSTICK_PRIORITY);
    let (card, loaded) = card_and_config(scenario);
    let config: &'static Config = CONFIG.init(loaded.config);
    if scenario.bench_detector {
        bench_detector(&mut ride.borrow_mut(), config)
    }
    let t_us = Instant::now().as_micros();
    for fault in loaded.faults.records(t_us) {
        QUEUE.push(Record::Fault(fault));
    }
    let high = executor::start_high(&mut cp.SCB, SAMPLER_PRIORITY);
    high.spawn(sampler_task(ride, scenario, config).expect("one sampler task"));
    let medium = executor::start_medium(&mut cp.NVIC, GPS_PRIORITY);
    medium.spawn(gps_task(scenario).expect("one GPS task"));
    executor::run_thread(|spawner| {
        spawner.spawn(writer_task(card, config).expect("one writer task"));
    })
}
