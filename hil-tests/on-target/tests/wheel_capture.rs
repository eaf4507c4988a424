//! The wheel adapter on the real TIM5: a 240 Hz PWM (the highest edge rate,
//! 10 m/s) looped back from PB6 to PA0 gives edges 4167 µs apart, also
//! across the 32-bit timer's wrap.
#![no_std]
#![no_main]

use defmt_rtt as _;

#[cfg(test)]
#[embedded_test::tests]
mod tests {
    use embassy_stm32::gpio::OutputType;
    use embassy_stm32::pac;
    use embassy_stm32::time::Hertz;
    use embassy_stm32::timer::low_level::CountingMode;
    use embassy_stm32::timer::simple_pwm::{PwmPin, SimplePwm};
    use embassy_time::Timer;
    use wobble_core::app::ports::WheelPort;
    use wobble_stm32f405::adapters::wheel::{self, WheelAdapter};

    /// 240 Hz: 4166.7 µs between falling edges.
    const PWM_HZ: u32 = 240;
    const INTERVAL_US: u64 = 1_000_000 / PWM_HZ as u64;

    /// Starts the PWM and the capture; returns them (kept running) and the
    /// adapter.
    fn bench() -> (
        SimplePwm<'static, embassy_stm32::peripherals::TIM4>,
        wheel::WheelTimer,
    ) {
        let (board, source) = wobble_on_target::board();
        let mut pwm = SimplePwm::new(
            source.timer,
            Some(PwmPin::new(source.pin, OutputType::PushPull)),
            None,
            None,
            None,
            Hertz(PWM_HZ),
            CountingMode::EdgeAlignedUp,
        );
        pwm.ch1().set_duty_cycle_percent(50);
        pwm.ch1().enable();
        (pwm, wheel::start(board.wheel))
    }

    /// Collects edge times for `ms`.
    async fn edges(adapter: &mut WheelAdapter, ms: u64) -> heapless::Vec<u64, 512> {
        let mut out = heapless::Vec::new();
        for _ in 0..ms / 10 {
            Timer::after_millis(10).await;
            adapter.drain_edges(&mut |t| {
                let _ = out.push(t);
            });
        }
        out
    }

    fn assert_regular(times: &[u64]) {
        defmt::assert!(times.len() > 200, "{} edges", times.len());
        for pair in times.windows(2) {
            let dt = pair[1] - pair[0];
            // The 1 µs capture resolution, and the PWM's own rounding.
            defmt::assert!(dt.abs_diff(INTERVAL_US) <= 2, "interval {} us", dt);
        }
    }

    #[test]
    async fn edges_at_240_hz_are_4167_us_apart() {
        let (_pwm, _timer) = bench();
        let mut adapter = WheelAdapter::default();
        assert_regular(&edges(&mut adapter, 1_000).await);
    }

    #[test]
    async fn edges_stay_exact_across_the_timer_wrap() {
        let (_pwm, _timer) = bench();
        // 0.5 s before the 32-bit counter wraps.
        pac::TIM5.cnt().write_value(u32::MAX - 500_000);
        let mut adapter = WheelAdapter::default();
        assert_regular(&edges(&mut adapter, 1_000).await);
        defmt::assert!(pac::TIM5.cnt().read() < 1_000_000, "the counter wrapped");
    }
}
