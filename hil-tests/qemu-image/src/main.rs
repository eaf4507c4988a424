//! The logger's core tasks on QEMU's `netduinoplus2` (STM32F405): the same
//! sampler, GPS and writer tasks as the board, with fixture-replaying
//! sensors and a semihosted FAT32 card image. Reports to the harness on
//! semihosting stdout; QEMU's exit code is the run's outcome (0 done,
//! 2 bad scenario, 3 power cut).
#![no_std]
#![no_main]

mod card;
mod executor;
mod replay;
mod report;
mod scenario;
mod time_driver;

use core::cell::RefCell;
use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m_rt::entry;
use embassy_time::Instant;
use static_cell::StaticCell;
use wobble_core::app::ports::{AlertOutput, LoggerHealth, StatusLed};
use wobble_core::app::sampler::{Sampler, SamplerPorts};
use wobble_core::app::{gps, sampler, writer};
use wobble_core::channels::{RecordQueue, SharedStatus};
use wobble_core::config::{Config, KEY_COUNT, MAX_TEXT_LEN};
use wobble_core::frame_assembly::FrameConfig;
use wobble_core::gps::{GpsConfig, GpsReceiver};
use wobble_core::logger::{
    CardLogger, FixedTime, HeaderSpec, LoggerConfig, FAULT_CARD_ABSENT, FAULT_CARD_FULL,
    FAULT_CARD_WRITE,
};
use wobble_core::wheel::WheelSpeed;

use crate::card::SemihostingCard;
use crate::replay::{Gps, Port, Ride};
use crate::scenario::Scenario;

/// Frames the sampler has taken (for the power-cut report).
pub static FRAMES_SAMPLED: AtomicU32 = AtomicU32::new(0);
static QUEUE: RecordQueue = RecordQueue::new();
static SHARED: SharedStatus = SharedStatus::new();
static MAX_LATE_US: AtomicU32 = AtomicU32::new(0);

/// NVIC priorities (4 bits on the STM32F4, upper nibble; lower value wins):
/// the time driver above the sampler, the sampler above thread mode.
const SYSTICK_PRIORITY: u8 = 0x40;
const SAMPLER_PRIORITY: u8 = 0x80;

/// The configuration in force: the defaults, as on a card without
/// `CONFIG.TXT` (the image's card holds only the log).
fn config() -> Config {
    Config::default()
}

/// The configuration's `key=value` lines for the log header, as the board
/// writes them.
fn config_lines() -> &'static [&'static str] {
    static TEXT: StaticCell<heapless::String<MAX_TEXT_LEN>> = StaticCell::new();
    static LINES: StaticCell<heapless::Vec<&'static str, KEY_COUNT>> = StaticCell::new();
    let text = TEXT.init(heapless::String::new());
    if config().write_lines(text).is_err() {
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

#[embassy_executor::task]
async fn sampler_task(ride: &'static RefCell<Ride>, frames: u32) {
    let config = config();
    let (Ok(wheel), Ok(detector)) = (WheelSpeed::try_new(config.wheel), config.detector()) else {
        report::line(format_args!("FATAL default configuration rejected"));
        semihosting::process::exit(2)
    };
    let mut s = Sampler::new(wheel, FrameConfig::DEFAULT, detector, config.alert.pattern);
    let mut ports = SamplerPorts {
        imu: Port(ride),
        steering: Port(ride),
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
        frames,
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
async fn writer_task(scenario: &'static Scenario) {
    let header = HeaderSpec {
        firmware: concat!("wobble-qemu-image ", env!("CARGO_PKG_VERSION")),
        device_id: *b"QEMU-NETDUI2",
        sample_rate_hz: 100,
        config: config_lines(),
    };
    let card = SemihostingCard::open(scenario);
    let mut logger = CardLogger::new(card, FixedTime::EPOCH, header, LoggerConfig::DEFAULT);
    let closed = writer::run(&mut logger, &QUEUE, &SHARED).await;
    let st = logger.stats();
    report::line(format_args!(
        "END frames={} t_us={} max_late_us={} queue_high_water={} queue_frames_dropped={} \
         card_frames_lost={} card_absent={} card_write_failed={} card_full={} files={} closed={}",
        FRAMES_SAMPLED.load(Ordering::Relaxed),
        Instant::now().as_micros(),
        MAX_LATE_US.load(Ordering::Relaxed),
        QUEUE.high_water(),
        QUEUE.frames_dropped_pending(),
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

/// Most steering samples the detector benchmark holds.
const BENCH_SAMPLES: usize = 3000;

/// Times the wobble detector alone over the ride's steering at 4 m/s:
/// `BENCH detector samples=N us=T`, virtual time, which the harness turns
/// into instructions. The samples are read first, so no file access is
/// timed.
fn bench_detector(ride: &mut Ride) -> ! {
    static SAMPLES: StaticCell<heapless::Vec<f32, BENCH_SAMPLES>> = StaticCell::new();
    let samples = SAMPLES.init(heapless::Vec::new());
    while let Some(deg) = ride.next_steer_deg() {
        if samples.push(deg).is_err() {
            break;
        }
    }
    let Ok(mut detector) = config().detector() else {
        report::line(format_args!("FATAL default configuration rejected"));
        semihosting::process::exit(2)
    };
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
    let ride: &'static RefCell<Ride> = RIDE.init(RefCell::new(Ride::open(scenario)));
    time_driver::init(cp.SYST, &mut cp.SCB, SYSTICK_PRIORITY);
    if scenario.bench_detector {
        bench_detector(&mut ride.borrow_mut())
    }
    let high = executor::start_high(&mut cp.SCB, SAMPLER_PRIORITY);
    high.spawn(sampler_task(ride, scenario.frames).expect("one sampler task"));
    executor::run_thread(|spawner| {
        spawner.spawn(writer_task(scenario).expect("one writer task"));
        spawner.spawn(gps_task(scenario).expect("one GPS task"));
    })
}
