//! `init` sends the datasheet's configuration sequence: identity check, soft
//! reset, 42 Hz anti-alias filters (banks 1 and 2), ranges and 100 Hz rate,
//! 3rd-order 40 Hz UI filters, low-noise mode, start-up wait.

mod icm42688_support;

use embassy_futures::block_on;
use embedded_hal_mock::eh1::delay::{CheckedDelay, Transaction as Delay};
use embedded_hal_mock::eh1::spi::Mock;
use icm42688_support::init_sequence;
use wobble_core::drivers::icm42688::{Config, GyroRange, Icm42688};

fn run(config: Config, gyro_config0: u8, accel_config0: u8) {
    let mut spi = Mock::new(&init_sequence(gyro_config0, accel_config0));
    let mut delay =
        CheckedDelay::new(&[Delay::async_delay_us(1_000), Delay::async_delay_us(45_000)]);
    let mut imu = Icm42688::new(spi.clone(), config);
    block_on(imu.init(&mut delay)).expect("init");
    spi.done();
    delay.done();
}

#[test]
fn default_is_16g_500dps_at_100hz() {
    // FS_SEL in bits 7:5 (gyro 2 = ±500 dps, accel 0 = ±16 g), ODR 8 = 100 Hz.
    run(Config::default(), 0x48, 0x08);
}

#[test]
fn a_wider_gyro_range_lands_in_its_fs_field() {
    let config = Config {
        gyro_range: GyroRange::Dps1000,
    };
    run(config, 0x28, 0x08);
}
