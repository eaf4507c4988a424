//! `init` sends the datasheet's configuration sequence: identity check, soft
//! reset, 42 Hz anti-alias filters (banks 1 and 2), ranges and 100 Hz rate,
//! 3rd-order 40 Hz UI filters, low-noise mode, start-up wait.

mod icm42688_support;

use embassy_futures::block_on;
use embedded_hal_mock::eh1::delay::{CheckedDelay, Transaction as Delay};
use embedded_hal_mock::eh1::spi::{Mock, Transaction};
use icm42688_support::{read_regs, write_reg};
use wobble_core::drivers::icm42688::{reg::*, Config, GyroRange, Icm42688};

/// Reset values of the two filter-order registers (datasheet section 14).
const GYRO_CONFIG1_RESET: u8 = 0x16;
const ACCEL_CONFIG1_RESET: u8 = 0x0D;

fn expected(gyro_config0: u8, accel_config0: u8) -> Vec<Transaction<u8>> {
    [
        write_reg(REG_BANK_SEL, 0),
        read_regs(WHO_AM_I, &[0x47]),
        write_reg(DEVICE_CONFIG, 0x01),
        // Bank 1, gyro AAF at 42 Hz: DELT 1, DELTSQR 1, BITSHIFT 15.
        write_reg(REG_BANK_SEL, 1),
        write_reg(GYRO_CONFIG_STATIC3, 1),
        write_reg(GYRO_CONFIG_STATIC4, 1),
        write_reg(GYRO_CONFIG_STATIC5, 0xF0),
        // Bank 2, accel AAF: DELT in bits 6:1, enable bit 0 clear.
        write_reg(REG_BANK_SEL, 2),
        write_reg(ACCEL_CONFIG_STATIC2, 0x02),
        write_reg(ACCEL_CONFIG_STATIC3, 1),
        write_reg(ACCEL_CONFIG_STATIC4, 0xF0),
        write_reg(REG_BANK_SEL, 0),
        write_reg(GYRO_CONFIG0, gyro_config0),
        write_reg(ACCEL_CONFIG0, accel_config0),
        // UI filter order 3rd (2) in bits 3:2 and 4:3, reserved bits kept.
        read_regs(GYRO_CONFIG1, &[GYRO_CONFIG1_RESET]),
        write_reg(GYRO_CONFIG1, 0x1A),
        read_regs(ACCEL_CONFIG1, &[ACCEL_CONFIG1_RESET]),
        write_reg(ACCEL_CONFIG1, 0x15),
        // Both UI bandwidths index 4: 400 Hz / 10.
        write_reg(GYRO_ACCEL_CONFIG0, 0x44),
        write_reg(PWR_MGMT0, 0x0F),
    ]
    .concat()
}

fn run(config: Config, gyro_config0: u8, accel_config0: u8) {
    let mut spi = Mock::new(&expected(gyro_config0, accel_config0));
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
