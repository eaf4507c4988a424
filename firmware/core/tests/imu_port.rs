//! The IMU port the board and the QEMU image share: the driver's samples
//! through the channel, and the recovery policy: a sensor that freezes or
//! goes away is set up again, at most once per `RETRY`, and between
//! attempts nothing is sent on the bus (the mock fails on any traffic it
//! was not told of).

mod icm42688_support;

use embassy_futures::block_on;
use embassy_time::{Duration, MockDriver};
use embedded_hal_mock::eh1::delay::NoopDelay;
use embedded_hal_mock::eh1::spi::{Mock, Transaction};
use icm42688_support::{data_read, init_sequence, read_regs, write_reg};
use wobble_core::app::imu_port::{Icm42688Port, RETRY};
use wobble_core::app::ports::{ImuPort, SensorError};
use wobble_core::drivers::icm42688::{reg, Config, Icm42688};
use wobble_core::imu::{Imu, ImuConfig};

/// `init`'s traffic for the default configuration (±500 deg/s, ±16 g,
/// 100 Hz).
fn init() -> Vec<Transaction<u8>> {
    init_sequence(0x48, 0x08)
}

const LIVE: [i16; 6] = [10, -20, 2048, 131, 0, -65];

fn port(expected: &[Transaction<u8>]) -> (Mock<u8>, Icm42688Port<Mock<u8>, NoopDelay>) {
    let spi = Mock::new(expected);
    let config = Config::default();
    let channel = Imu::try_new(config.imu_config(ImuConfig::DEFAULT)).expect("ranges");
    let port = Icm42688Port::new(
        Icm42688::new(spi.clone(), config),
        channel,
        NoopDelay::new(),
    );
    (spi, port)
}

// One test: the mock clock is shared by every test of this binary.
#[test]
fn stuck_and_vanished_sensors_are_set_up_again_once_per_retry() {
    let clock = MockDriver::get();
    // `start` alone sets the sensor up, before the sampler's first tick.
    let (mut spi, mut port_started) = port(&init());
    block_on(port_started.start());
    spi.done();

    let stuck = usize::from(ImuConfig::DEFAULT.stuck_samples);
    let mut traffic = init();
    traffic.extend(data_read(LIVE));
    // Frozen output: `stuck` identical samples.
    for _ in 0..stuck {
        traffic.extend(data_read([1, 2, 3, 4, 5, 6]));
    }
    // Set up again at the next read (a second after the first set-up),
    // then live.
    traffic.extend(init());
    traffic.extend(data_read(LIVE));
    // The sensor goes away: the floating bus, then a failed identity check.
    traffic.extend(data_read([-1; 6]));
    traffic.extend(write_reg(reg::REG_BANK_SEL, 0));
    traffic.extend(read_regs(reg::WHO_AM_I, &[0xFF]));
    // Back a retry later.
    traffic.extend(init());
    traffic.extend(data_read(LIVE));
    // The self-test's identity read.
    traffic.extend(write_reg(reg::REG_BANK_SEL, 0));
    traffic.extend(read_regs(reg::WHO_AM_I, &[reg::WHO_AM_I_VALUE]));
    let (mut spi, mut port) = port(&traffic);

    block_on(port.start());
    let first = block_on(port.read(0)).expect("live sample");
    assert!((first.accel_g[2] - 1.0).abs() < 1e-6 && (first.gyro_dps[0] - 2.0).abs() < 1e-6);
    for k in 1..=stuck {
        let s = block_on(port.read(0)).expect("a sample");
        assert_eq!(s.stuck, k == stuck, "sample {k}");
    }
    clock.advance(RETRY);
    assert!(!block_on(port.read(0)).expect("set up again, live").stuck);

    assert_eq!(
        block_on(port.read(0)),
        Err(SensorError::NoResponse),
        "floating bus"
    );
    clock.advance(RETRY);
    assert_eq!(
        block_on(port.read(0)),
        Err(SensorError::NoResponse),
        "identity check failed"
    );
    // Within the retry period: no traffic at all.
    clock.advance(RETRY - Duration::from_millis(10));
    assert_eq!(block_on(port.read(0)), Err(SensorError::NoResponse));
    clock.advance(Duration::from_millis(10));
    assert!(
        block_on(port.read(0)).is_ok(),
        "set up again a retry after the failure"
    );
    assert_eq!(block_on(port.identity()), Some(reg::WHO_AM_I_VALUE));
    spi.done();
}
