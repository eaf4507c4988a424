//! The sampler's work per frame on the real core, counted by the cycle
//! counter (DWT CYCCNT) with the chip brought up as the logger brings it up
//! (168 MHz, flash accelerator on): 60 s of frames at 5 m/s with a decaying
//! 7 Hz steering ring every 3 s (a kick: its ring-down fit, the damping trend
//! and the margin estimate run on board) and a growing wobble at the end
//! (the alert). The worst frame must stay under a fifth of the 10 ms period,
//! where the sampler's executor would start to delay the next frame's
//! sampling; the mean and worst are printed for `board.md`.
#![no_std]
#![no_main]

use defmt_rtt as _;

#[cfg(test)]
#[embedded_test::tests]
mod tests {
    use cortex_m::peripheral::DWT;
    use wobble_core::app::ports::{ImuSample, SteeringSample};
    use wobble_core::app::sampler::{Inputs, Sampler, FRAME_PERIOD_US};
    use wobble_core::config::{AlertConfig, Config};
    use wobble_core::detector::AlertOutput;
    use wobble_core::frame_assembly::FrameConfig;
    use wobble_core::wheel::{WheelConfig, WheelSpeed};

    /// Core clock, Hz.
    const CORE_HZ: u64 = 168_000_000;
    /// Frames ridden: 60 s.
    const FRAMES: u64 = 6000;
    /// Forward speed, m/s.
    const SPEED_MPS: f64 = 5.0;

    struct Quiet;

    impl AlertOutput for Quiet {
        fn set_buzzer(&mut self, _: bool) {}
        fn set_led(&mut self, _: bool) {}
    }

    /// The steering angle at `t_s`: a kick every 3 s ringing down at 7 Hz
    /// (sigma -1.5 1/s), then from 50 s a 7 Hz wobble growing at 1 1/s.
    fn steer_deg(t_s: f64) -> f32 {
        let w = core::f64::consts::TAU * 7.0;
        let ring = {
            let since = t_s % 3.0;
            2.0 * libm::exp(-1.5 * since) * libm::sin(w * since)
        };
        let wobble = if t_s > 50.0 {
            0.1 * libm::exp(t_s - 50.0) * libm::sin(w * t_s)
        } else {
            0.0
        };
        (ring + wobble.clamp(-20.0, 20.0)) as f32
    }

    #[test]
    fn the_worst_frame_takes_under_a_fifth_of_the_period() {
        let _ = wobble_on_target::board();
        // SAFETY: the cycle counter is used by nothing else in this test.
        let mut core = unsafe { cortex_m::Peripherals::steal() };
        core.DCB.enable_trace();
        core.DWT.enable_cycle_counter();
        let wheel = WheelConfig::DEFAULT;
        let mut sampler = Sampler::new(
            defmt::unwrap!(WheelSpeed::try_new(wheel).ok()),
            FrameConfig::DEFAULT,
            defmt::unwrap!(Config::default().detector().ok()),
            AlertConfig::default(),
        );
        // Wheel edges at the ride's speed, between the frames.
        let edge_us = f64::from(wheel.circumference_m) / f64::from(wheel.holes) / SPEED_MPS * 1e6;
        let mut next_edge_us = 0.0;
        let (mut worst, mut total, mut records) = (0u32, 0u64, 0u32);
        for k in 1..=FRAMES {
            let now_us = k * FRAME_PERIOD_US;
            while next_edge_us < now_us as f64 {
                sampler.wheel_edge(next_edge_us as u64);
                next_edge_us += edge_us;
            }
            let inputs = Inputs {
                imu: Ok(ImuSample {
                    accel_g: [0.0, 0.0, 1.0],
                    gyro_dps: [0.0, 0.0, 0.0],
                    stuck: false,
                    skipped: 0,
                }),
                steering: Ok(SteeringSample {
                    deg: steer_deg(now_us as f64 / 1e6),
                    saturated: false,
                }),
                marker: false,
                last_gps_fix_us: Some(now_us),
            };
            let start = DWT::cycle_count();
            sampler.step(now_us, &inputs, &mut Quiet, &mut |_| records += 1);
            let cycles = DWT::cycle_count().wrapping_sub(start);
            worst = worst.max(cycles);
            total += u64::from(cycles);
        }
        let period_cycles = FRAME_PERIOD_US * CORE_HZ / 1_000_000;
        defmt::info!(
            "sampler step: mean {} cycles, worst {} cycles ({} us) of {} per frame; {} records",
            total / FRAMES,
            worst,
            u64::from(worst) * 1_000_000 / CORE_HZ,
            period_cycles,
            records
        );
        // Frames, kicks and the alert all went out.
        defmt::assert!(u64::from(records) > FRAMES + 10);
        defmt::assert!(u64::from(worst) < period_cycles / 5);
    }
}
