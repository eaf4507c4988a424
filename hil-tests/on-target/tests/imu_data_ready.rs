//! The IMU on its own clock, on the real sensor: the ICM-42688-P's INT1
//! (PA1, no loop-back needed, the board's wiring) pulses once per sample,
//! TIM5 channel 2 latches the times, and the port pairs each FIFO sample
//! with its pulse (`wobble_core::imu_clock`).
#![no_std]
#![no_main]

use defmt_rtt as _;

#[cfg(test)]
#[embedded_test::tests]
mod tests {
    use embassy_time::{Duration, Instant, Ticker, Timer};
    use wobble_core::app::ports::{DataReadyPort, ImuPort};
    use wobble_core::imu::ImuConfig;
    use wobble_core::imu_clock::NOMINAL_PERIOD_US;
    use wobble_stm32f405::adapters::imu::{self, DataReadyAdapter, ImuAdapter};
    use wobble_stm32f405::adapters::wheel::{self, WheelTimer};

    /// The sensor's oscillator is within a few per cent of 100 Hz.
    const PERIOD_TOLERANCE: f32 = 0.03;

    /// The IMU port as the logger builds it, and the running capture timer.
    fn imu() -> (ImuAdapter, WheelTimer) {
        let (board, _) = wobble_on_target::board();
        let timer = wheel::start(board.wheel);
        let port = imu::port(board.imu, ImuConfig::DEFAULT);
        (port, timer)
    }

    #[test]
    async fn pulses_come_once_per_sample_at_the_sensor_rate() {
        let (mut port, _timer) = imu();
        port.start().await;
        // Through the port's own data-ready adapter would pair them; here,
        // a second adapter reads the raw pulse times for 2 s.
        let mut pulses = DataReadyAdapter::default();
        let mut times: heapless::Vec<u64, 256> = heapless::Vec::new();
        for _ in 0..200 {
            Timer::after_millis(10).await;
            pulses.drain_pulses(&mut |t| times.push(t).is_ok());
        }
        defmt::assert!(times.len() >= 190, "{} pulses in 2 s", times.len());
        let span = (times[times.len() - 1] - times[0]) as f32;
        let period = span / (times.len() - 1) as f32;
        defmt::info!("sensor period {} us", period);
        let nominal = NOMINAL_PERIOD_US as f32;
        defmt::assert!(
            (period / nominal - 1.0).abs() < PERIOD_TOLERANCE,
            "period {} us",
            period
        );
        // One pulse per period, none missing or doubled: each interval is
        // the mean to within 1 % (the oscillator is stable over seconds).
        for pair in times.windows(2) {
            let dt = (pair[1] - pair[0]) as f32;
            defmt::assert!((dt / period - 1.0).abs() < 0.01, "interval {} us", dt);
        }
        defmt::assert_eq!(pulses.losses(), (0, 0));
    }

    #[test]
    async fn every_sample_reaches_a_frame_at_a_fixed_age() {
        let (mut port, _timer) = imu();
        port.start().await;
        let mut ticker = Ticker::every(Duration::from_micros(10_000));
        let start = Instant::now().as_micros();
        let mut live = 0u32;
        for k in 1..=500u64 {
            ticker.next().await;
            if let Ok(s) = port.read(start + k * 10_000).await {
                defmt::assert_eq!(s.skipped, 0, "frame {}", k);
                live += 1;
            }
        }
        let (stats, period) = port.clock();
        defmt::info!("{} live frames, {}, period {} us", live, stats, period);
        // The first frame or two come before the first sample after the
        // set-up's FIFO flush.
        defmt::assert!(live >= 497, "{} live frames of 500", live);
        defmt::assert_eq!(stats.skipped, 0);
        defmt::assert_eq!(stats.untimed, 0);
        defmt::assert!(stats.samples >= 490, "{} samples in 5 s", stats.samples);
        let nominal = NOMINAL_PERIOD_US as f32;
        defmt::assert!((period / nominal - 1.0).abs() < PERIOD_TOLERANCE);
    }
}
