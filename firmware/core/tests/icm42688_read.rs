//! `read` takes one 12-byte burst from ACCEL_DATA_X1, big-endian words in
//! the order accel x y z, gyro x y z; the configured ranges give the
//! datasheet sensitivities the IMU channel scales them with.

mod icm42688_support;

use embassy_futures::block_on;
use embedded_hal_mock::eh1::spi::Mock;
use icm42688_support::data_read;
use wobble_core::drivers::icm42688::{Config, GyroRange, Icm42688};
use wobble_core::imu::{Imu, ImuConfig};

fn read_scaled(config: Config, words: [i16; 6]) -> ([f32; 3], [f32; 3]) {
    let mut spi = Mock::new(&data_read(words));
    let mut imu = Icm42688::new(spi.clone(), config);
    let raw = block_on(imu.read()).expect("read");
    spi.done();
    assert_eq!(raw.accel, [words[0], words[1], words[2]]);
    assert_eq!(raw.gyro, [words[3], words[4], words[5]]);
    let mut channel = Imu::try_new(config.imu_config(ImuConfig::DEFAULT)).expect("ranges");
    channel.push(raw);
    let sample = channel.take().expect("one sample");
    (sample.accel_g, sample.gyro_dps)
}

fn close(a: [f32; 3], b: [f32; 3]) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-4)
}

#[test]
fn words_are_big_endian_and_scaled_at_16g_500dps() {
    // -0.5 g on x, 1 g on z; 100 deg/s about y (65.5 LSB per deg/s).
    let (accel, gyro) = read_scaled(Config::default(), [-1024, 3, 2048, -131, 6550, 0]);
    assert!(close(accel, [-0.5, 3.0 / 2048.0, 1.0]), "{accel:?}");
    assert!(close(gyro, [-2.0, 100.0, 0.0]), "{gyro:?}");
}

#[test]
fn gyro_scale_follows_the_configured_range() {
    let config = Config {
        gyro_range: GyroRange::Dps1000,
    };
    let (accel, gyro) = read_scaled(config, [4096, 0, 0, 328, 0, 0]);
    assert!(close(accel, [2.0, 0.0, 0.0]), "{accel:?}");
    assert!(close(gyro, [10.0, 0.0, 0.0]), "{gyro:?}");
}
