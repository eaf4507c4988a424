//! The field self-test on the board: gathers the core's
//! `selftest::Measurements` from the adapters, writes `SELFTEST.TXT` and
//! shows the result. What counts as a pass is the core's.
//!
//! Started instead of logging when the marker button is held at power-on.
//! The status LED blinks fast while the rider turns the handlebar and spins
//! the wheel (10 s); the GPS bring-up runs meanwhile. Then: all passed,
//! green LED on and one long beep; a failure, the red LED and the buzzer
//! repeat the failing check's number (1 IMU, 2 steering, 3 wheel, 4 GPS,
//! 5 card, 6 clock, 7 reset, 8 brown-out level, 9 stack, 10 IMU data-ready
//! line, 11 record queue: the card too slow for it, 12 supply too low for
//! the brown-out level) until power-off.
//! The brown-out level is programmed here when it is below 2.7 V (never at
//! boot) and the supply, measured through VREFINT just before, is high
//! enough for it (the core's `supply`; the report's `vdd` line, LED code
//! 12 when too low): the check fails until a power cycle and a second
//! self-test show the stored level.

use embassy_futures::join::join;
use embassy_stm32::gpio::Output;
use embassy_stm32::peripherals::ADC1;
use embassy_time::{Duration, Instant, Ticker, Timer};
use embedded_sdmmc::{Mode, VolumeIdx};
use wobble_core::app::gps_setup;
use wobble_core::app::ports::{DataReadyPort, ImuPort, SteeringPort, WheelPort};
use wobble_core::boot::ResetCause;
use wobble_core::channels::{RecordQueue, QUEUE_LEN};
use wobble_core::detector::math::sqrtf;
use wobble_core::logger::{self, FixedTime, Volumes};
use wobble_core::selftest::{
    fat_free_mib, overall_code, write_report, Measurements, PulseTrain, QueueCheck,
    DATA_READY_WINDOW_US, TEST_WINDOW_US,
};
use wobble_core::supply::SupplyCheck;

use crate::adapters::card::SdCard;
use crate::adapters::gps::GpsAdapter;
use crate::adapters::imu::{DataReadyAdapter, ImuAdapter};
use crate::adapters::steering::SteeringAdapter;
use crate::adapters::wheel::WheelAdapter;

/// Everything the self-test uses.
pub struct Parts {
    /// The IMU.
    pub imu: ImuAdapter,
    /// The steering ADC.
    pub steering: SteeringAdapter,
    /// The wheel capture (its timer already started).
    pub wheel: WheelAdapter,
    /// The GPS UART.
    pub gps: GpsAdapter,
    /// The card.
    pub card: SdCard,
    /// Buzzer, red LED, green LED.
    pub buzzer: Output<'static>,
    /// Red LED.
    pub alert_led: Output<'static>,
    /// Green LED.
    pub status_led: Output<'static>,
    /// Whether the crystal runs.
    pub crystal: bool,
    /// Why the MCU reset.
    pub reset: ResetCause,
}

/// Blocks written and read for the speed figure (64 KiB).
const SPEED_BLOCKS: u32 = 128;
const SCRATCH: &str = "SELFTEST.BIN";
const REPORT: &str = "SELFTEST.TXT";

/// Mean acceleration magnitude over a second at rest, g.
async fn imu_at_rest(imu: &mut ImuAdapter) -> Option<f32> {
    let mut ticker = Ticker::every(Duration::from_millis(10));
    let (mut sum, mut n) = (0.0f32, 0u32);
    for _ in 0..100 {
        ticker.next().await;
        if let Ok(s) = imu.read(Instant::now().as_micros()).await {
            let [x, y, z] = s.accel_g;
            sum += sqrtf(x * x + y * y + z * z);
            n += 1;
        }
    }
    (n > 0).then(|| sum / n as f32)
}

/// The IMU's data-ready pulses (INT1, captured by TIM5 channel 2) over
/// [`DATA_READY_WINDOW_US`], after the port has set the sensor up. The port
/// does not read meanwhile, so a second adapter on the same capture queue
/// sees every pulse; the pass/fail rule is the core's
/// (`PulseTrain::at_rate`).
async fn data_ready_pulses() -> PulseTrain {
    let mut line = DataReadyAdapter::default();
    // What the port left in the queue is older than the window.
    line.drain_pulses(&mut |_| true);
    let mut train = PulseTrain::default();
    let mut ticker = Ticker::every(Duration::from_millis(10));
    let end = Instant::now() + Duration::from_micros(DATA_READY_WINDOW_US);
    while Instant::now() < end {
        ticker.next().await;
        line.drain_pulses(&mut |t| {
            train.pulse(t);
            true
        });
    }
    train
}

/// Steering range and wheel edges over the test window, status LED
/// blinking fast.
async fn sensors(
    steering: &mut SteeringAdapter,
    wheel: &mut WheelAdapter,
    led: &mut Output<'static>,
    m: &mut Measurements,
) {
    let mut ticker = Ticker::every(Duration::from_millis(10));
    let end = Instant::now() + Duration::from_micros(TEST_WINDOW_US);
    let mut k = 0u32;
    while Instant::now() < end {
        ticker.next().await;
        k += 1;
        led.set_level((k / 10).is_multiple_of(2).into());
        if steering.read(0).await.is_ok() {
            if let Some((lo, hi)) = steering.last_range() {
                let (a, b) = m.steer_counts.unwrap_or((lo, hi));
                m.steer_counts = Some((a.min(lo), b.max(hi)));
            }
        }
        wheel.drain_edges(&mut |_| m.wheel_edges += 1);
    }
    led.set_low();
}

/// Write and read speed, KiB/s, and the slowest single block write, µs,
/// through a scratch file that is deleted afterwards (logs are never
/// touched).
fn card_speed(volumes: &Volumes<SdCard, FixedTime>) -> Option<(u32, u32, u32)> {
    let volume = volumes.open_volume(VolumeIdx(0)).ok()?;
    let root = volume.open_root_dir().ok()?;
    let block = [0x5Au8; 512];
    let kib_s = |start: Instant| {
        let us = Instant::now().duration_since(start).as_micros().max(1);
        (u64::from(SPEED_BLOCKS) * 512 * 1_000_000 / 1024 / us) as u32
    };
    let start = Instant::now();
    let mut slowest_us = 0u64;
    {
        let file = root
            .open_file_in_dir(SCRATCH, Mode::ReadWriteCreateOrTruncate)
            .ok()?;
        for _ in 0..SPEED_BLOCKS {
            let write_start = Instant::now();
            file.write(&block).ok()?;
            slowest_us = slowest_us.max(Instant::now().duration_since(write_start).as_micros());
        }
        file.close().ok()?;
    }
    let write = kib_s(start);
    let start = Instant::now();
    {
        let file = root.open_file_in_dir(SCRATCH, Mode::ReadOnly).ok()?;
        let mut back = [0u8; 512];
        for _ in 0..SPEED_BLOCKS {
            if file.read(&mut back).ok()? != 512 || back != block {
                return None;
            }
        }
        file.close().ok()?;
    }
    let read = kib_s(start);
    root.delete_entry_in_dir(SCRATCH).ok()?;
    Some((write, read, u32::try_from(slowest_us).unwrap_or(u32::MAX)))
}

fn write_report_file(volumes: &Volumes<SdCard, FixedTime>, text: &str) -> bool {
    let write = || -> Option<()> {
        let volume = volumes.open_volume(VolumeIdx(0)).ok()?;
        let root = volume.open_root_dir().ok()?;
        let file = root
            .open_file_in_dir(REPORT, Mode::ReadWriteCreateOrTruncate)
            .ok()?;
        file.write(text.as_bytes()).ok()?;
        file.close().ok()
    };
    write().is_some()
}

/// Beeps and blinks `code` times.
async fn show(led: &mut Output<'static>, buzzer: &mut Output<'static>, code: u8) {
    for _ in 0..code {
        led.set_high();
        buzzer.set_high();
        Timer::after_millis(200).await;
        led.set_low();
        buzzer.set_low();
        Timer::after_millis(300).await;
    }
    Timer::after_secs(2).await;
}

/// Runs the self-test, then shows its result until power-off. `queue` is
/// the ride's record queue (in CCM), whose capacity and high-water mark
/// this boot the report's `queue` line gives.
pub async fn run(p: Parts, queue: &'static RecordQueue) -> ! {
    let Parts {
        mut imu,
        mut steering,
        mut wheel,
        mut gps,
        card,
        mut buzzer,
        mut alert_led,
        mut status_led,
        crystal,
        reset,
    } = p;
    defmt::info!("self-test: hold still, then turn the handlebar and spin the wheel");
    let mut m = Measurements {
        crystal,
        reset: Some(reset),
        ..Measurements::default()
    };
    // Raw, so the report names a wrong part by its identity.
    m.imu_id = imu.identity().await;
    m.accel_g = imu_at_rest(&mut imu).await;
    m.imu_data_ready = Some(data_ready_pulses().await);
    let (outcome, ()) = join(
        gps_setup::run(&mut gps, &mut |step| defmt::info!("GPS set-up: {}", step)),
        sensors(&mut steering, &mut wheel, &mut status_led, &mut m),
    )
    .await;
    m.gps_baud = outcome.found_baud;
    m.gps_rate_hz = outcome.rate_hz;
    // The steering ring is done with: its drop stops the conversions and
    // the DMA stream and gates ADC1's clock (embassy-stm32 0.6.0,
    // `RingBufferedAdc`'s and `ReadableRingBuffer`'s `Drop`).
    drop(steering);
    // SAFETY: ADC1's only user, the steering ring above, is gone (its
    // `Peri` was consumed into it at assembly); nothing else in the
    // self-test touches ADC1.
    let adc = unsafe { ADC1::steal() };
    let supply = SupplyCheck {
        reading: crate::adapters::supply::measure(adc),
    };
    defmt::info!("supply: {}", supply.reading);
    // The explicit step the boot never takes: the option bytes are written
    // here, at the bench, on a supply measured high enough, and verified
    // by the next self-test.
    m.bor = Some(crate::startup::program_bor_level3(supply.reading));
    m.stack_bytes = Some(crate::startup::stack_use());
    let volumes = logger::volumes(card, FixedTime::EPOCH);
    m.card_free_mib = volumes.device(|card| fat_free_mib(card)).unwrap_or(0);
    // The volume, opened and dropped (closed) at once: what the logger's
    // `open_fault` calls an unusable card.
    m.card_unusable = matches!(
        volumes.open_volume(VolumeIdx(0)),
        Err(embedded_sdmmc::Error::FormatError(_))
    );
    let speed = card_speed(&volumes);
    m.card_kib_s = speed.map(|(w, r, _)| (w, r));
    let queue = QueueCheck {
        capacity: QUEUE_LEN as u32,
        high_water: queue.high_water(),
        slowest_write_us: speed.map(|(_, _, slowest)| slowest),
    };
    let mut text = heapless::String::<1024>::new();
    if write_report(&m, &mut text).is_err()
        || queue.write_line(&mut text).is_err()
        || supply.write_line(&mut text).is_err()
    {
        defmt::warn!("self-test report cut short");
    }
    defmt::info!("{=str}", text.as_str());
    if !write_report_file(&volumes, &text) {
        defmt::error!("{} not written", REPORT);
    }
    let code = overall_code(&m, &queue, &supply);
    if code == 0 {
        status_led.set_high();
        buzzer.set_high();
        Timer::after_secs(1).await;
        buzzer.set_low();
    }
    loop {
        if code == 0 {
            Timer::after_secs(3600).await;
        } else {
            show(&mut alert_led, &mut buzzer, code).await;
        }
    }
}
