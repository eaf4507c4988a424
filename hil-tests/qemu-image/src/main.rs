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
use wobble_core::app::ports::{AlertOutput, LoggerHealth, SensorError, StatusLed};
use wobble_core::app::sampler::{Sampler, SamplerPorts};
use wobble_core::app::{gps, sampler, writer};
use wobble_core::channels::{RecordQueue, SharedStatus};
use wobble_core::config::{self, Config, Loaded, KEY_COUNT, MAX_TEXT_LEN};
use wobble_core::detector::MarginWarning;
use wobble_core::drivers::icm42688::{self, Icm42688};
use wobble_core::format::Record;
use wobble_core::frame_assembly::{FrameAssembler, FrameConfig, TickInputs};
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
    // A line of its own: the END line is near the report's 256 characters.
    let w = SHARED.writer();
    report::line(format_args!(
        "WRITER ops_max={} open_ops_max={} busy_max_us={}",
        w.ops_max, w.open_ops_max, w.busy_max_us
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

/// Times the wobble detector and the margin warning over the ride, as the
/// sampler runs them on each frame (`Sampler::step`): the frame's steering
/// angle and wheel speed, as the card stores them, into `Detector::push`,
/// the kick it reports into `MarginWarning::add_kick`, and the warning's
/// `update`. Only that work is timed (virtual time, which the harness turns
/// into instructions), not the reading of the ride nor the frame's
/// assembly: `BENCH detector samples=N ns=T max_ns=W max_at=K
/// kick_max_ns=.. margin_max_ns=.. alert_changes=.. kicks=.. estimates=..
/// clock_ns=..`,
/// where `max_at` is the sample (from 0) of the worst one, `kick_max_ns`
/// the worst sample that reported a kick (the ring-down fit and the margin
/// estimate run on it) and `margin_max_ns` the worst margin estimate alone.
fn bench_detector(ride: &mut Ride, config: &Config) -> ! {
    let (Ok(mut steering), Ok(mut detector), Ok(mut wheel)) = (
        Steering::try_new(config.steering),
        config.detector(),
        WheelSpeed::try_new(config.wheel),
    ) else {
        rejected()
    };
    let mut margin = MarginWarning::new(config.alert.margin_mps);
    let mut frames = FrameAssembler::new(FrameConfig::DEFAULT);
    let (mut samples, mut total_ns, mut max_ns, mut max_at) = (0u32, 0u64, 0u64, 0u32);
    let (mut kick_max_ns, mut margin_max_ns) = (0u64, 0u64);
    let (mut alerts, mut kicks, mut estimates) = (0u32, 0u32, 0u32);
    // What one reading of the clock costs: the least of a few back to back.
    let clock_ns = (0..8)
        .map(|_| {
            let t0 = time_driver::now_ns();
            time_driver::now_ns() - t0
        })
        .min()
        .unwrap_or(0);
    let mut t_us = 0u64;
    loop {
        t_us += sampler::FRAME_PERIOD_US;
        let now_us = t_us;
        let Some(steer) = ride.next_bench_row(&mut steering, &mut |age| {
            wheel.on_edge(now_us.saturating_sub(u64::from(age)));
        }) else {
            break;
        };
        let frame = frames.tick(
            t_us,
            &TickInputs {
                imu: Err(SensorError::Stale),
                steering: steer,
                wheel: wheel.sample(t_us),
                last_gps_fix_us: None,
                marker: false,
            },
        );
        let (deg, speed) = (frame.steer_deg(), Some(frame.speed_mps()));
        let start = time_driver::now_ns();
        let event = detector.push(deg, speed);
        let kick = detector.take_kick();
        let mut margin_ns = 0;
        if let Some(k) = kick {
            let t0 = time_driver::now_ns();
            estimates += u32::from(margin.add_kick(&k).is_some());
            margin_ns = (time_driver::now_ns() - t0).saturating_sub(clock_ns);
        }
        let _ = margin.update(t_us, speed);
        // The clock's own cost, and on a kick's sample that of the two
        // readings around the margin estimate, are taken out.
        let clocks = if kick.is_some() { 3 } else { 1 };
        let ns = (time_driver::now_ns() - start).saturating_sub(clocks * clock_ns);
        total_ns += ns;
        if ns > max_ns {
            (max_ns, max_at) = (ns, samples);
        }
        if kick.is_some() {
            kicks += 1;
            kick_max_ns = kick_max_ns.max(ns);
            margin_max_ns = margin_max_ns.max(margin_ns);
        }
        alerts += u32::from(event.is_some());
        samples += 1;
    }
    report::line(format_args!(
        "BENCH detector samples={samples} ns={total_ns} max_ns={max_ns} max_at={max_at} \
         kick_max_ns={kick_max_ns} margin_max_ns={margin_max_ns} alert_changes={alerts} \
         kicks={kicks} estimates={estimates} clock_ns={clock_ns}"
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
