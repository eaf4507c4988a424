//! A sensor that does not answer, or another part in its place, is reported
//! after the identity check and nothing is written to it; the identity
//! itself can be read raw; one that goes away after its set-up reads as the
//! floating bus, which is no sample.

mod icm42688_support;

use embassy_futures::block_on;
use embedded_hal_mock::eh1::delay::NoopDelay;
use embedded_hal_mock::eh1::spi::Mock;
use icm42688_support::{data_read, read_regs, write_reg};
use wobble_core::app::ports::SensorError;
use wobble_core::drivers::icm42688::{reg::*, Config, Error, Icm42688};

fn init_with_who_am_i(answer: u8) -> Error<embedded_hal::spi::ErrorKind> {
    let expectations = [write_reg(REG_BANK_SEL, 0), read_regs(WHO_AM_I, &[answer])].concat();
    let mut spi = Mock::new(&expectations);
    let mut imu = Icm42688::new(spi.clone(), Config::default());
    let err = block_on(imu.init(&mut NoopDelay::new())).expect_err("no sensor");
    spi.done();
    err
}

#[test]
fn floating_miso_reads_as_no_response() {
    // Pulled up (no sensor) and held low (sensor unpowered).
    for answer in [0xFF, 0x00] {
        let err = init_with_who_am_i(answer);
        assert_eq!(err, Error::NoResponse);
        assert_eq!(err.sensor_error(), SensorError::NoResponse);
    }
}

#[test]
fn another_part_is_named_by_its_id() {
    // 0x12: an ICM-20602 fitted instead.
    let err = init_with_who_am_i(0x12);
    assert_eq!(err, Error::WrongId(0x12));
    assert_eq!(err.sensor_error(), SensorError::NoResponse);
}

#[test]
fn a_sensor_gone_after_init_is_no_response_not_a_sample() {
    for word in [-1i16, 0] {
        let mut spi = Mock::new(&data_read([word; 6]));
        let mut imu = Icm42688::new(spi.clone(), Config::default());
        let err = block_on(imu.read()).expect_err("floating bus");
        spi.done();
        assert_eq!(err, Error::NoResponse);
        assert_eq!(err.sensor_error(), SensorError::NoResponse);
    }
    // One live word among the floating ones is a sample.
    let mut spi = Mock::new(&data_read([-1, -1, 2048, -1, -1, -1]));
    let mut imu = Icm42688::new(spi.clone(), Config::default());
    assert!(block_on(imu.read()).is_ok());
    spi.done();
}

#[test]
fn the_identity_is_read_raw_whatever_answers() {
    for answer in [WHO_AM_I_VALUE, 0x12, 0x00, 0xFF] {
        let expectations = [write_reg(REG_BANK_SEL, 0), read_regs(WHO_AM_I, &[answer])].concat();
        let mut spi = Mock::new(&expectations);
        let mut imu = Icm42688::new(spi.clone(), Config::default());
        assert_eq!(block_on(imu.who_am_i()), Ok(answer));
        spi.done();
    }
}
