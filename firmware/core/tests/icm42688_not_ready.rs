//! Data registers holding the "no data" marker (sensor off or just reset)
//! are reported as not ready; a single axis at full negative scale is not.

mod icm42688_support;

use embassy_futures::block_on;
use embedded_hal_mock::eh1::spi::Mock;
use icm42688_support::data_read;
use wobble_core::app::ports::SensorError;
use wobble_core::drivers::icm42688::{Config, Error, Icm42688};

#[test]
fn the_no_data_marker_is_not_ready() {
    let mut spi = Mock::new(&data_read([i16::MIN; 6]));
    let mut imu = Icm42688::new(spi.clone(), Config::default());
    let err = block_on(imu.read()).expect_err("no data");
    spi.done();
    assert_eq!(err, Error::NotReady);
    assert_eq!(err.sensor_error(), SensorError::Stale);
}

#[test]
fn one_saturated_axis_is_data() {
    let words = [i16::MIN, 0, 2048, 0, 0, 0];
    let mut spi = Mock::new(&data_read(words));
    let mut imu = Icm42688::new(spi.clone(), Config::default());
    let raw = block_on(imu.read()).expect("data");
    spi.done();
    assert_eq!(raw.accel, [i16::MIN, 0, 2048]);
}
