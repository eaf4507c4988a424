//! The time base across TIM5's 32-bit wrap (2³² µs: 71.6 min at 1 MHz).
//! The firmware keeps time with embassy-time on TIM3 (16 bits, extended by
//! its driver's period count: `time-driver-tim3`, 1 MHz ticks), and dates
//! every wheel edge and IMU data-ready pulse by TIM5's capture through the
//! core's `wheel_capture::EdgeClock` (`now − (counter − capture)`, in
//! wrapping 32-bit arithmetic). Both timers count the same 84 MHz timer
//! clock divided to 1 MHz, so they must stay in step, across the wrap too.
//!
//! Each 10 ms frame (an embassy-time `Ticker`, as the sampler's) reads
//! embassy-time's clock and TIM5's counter together and checks:
//! - the clock is monotonic and the frames are 10 ms apart (to 200 µs of
//!   wake-up lateness in thread mode);
//! - TIM5 advanced by what the clock advanced, ± 3 µs, wrap included;
//! - a capture of the counter at the frame, handed to the firmware's
//!   `EdgeClock` 50 µs later (as the TIM5 interrupt would), is dated the
//!   frame's time ± 3 µs; and so is each frame's capture handed to a
//!   second `EdgeClock` at the next frame, 10 ms later: at the wrap, a
//!   capture taken before it and read after it.
//!
//! The short test presets TIM5 0.5 s before the wrap, as `wheel_capture`
//! does. The soak test (`#[ignore]`d: 75 min) lets the counter run from 0
//! through a real wrap: `cargo test -p wobble-on-target --target
//! thumbv7em-none-eabihf --test tim5_wrap -- --include-ignored` (bench step
//! 11c in `firmware/docs/board.md`). No wiring.
#![no_std]
#![no_main]

use defmt_rtt as _;

#[cfg(test)]
#[embedded_test::tests]
mod tests {
    use embassy_stm32::pac;
    use embassy_time::{Duration, Instant, Ticker};
    use wobble_core::wheel_capture::{EdgeClock, RawCapture};
    use wobble_stm32f405::adapters::wheel;

    const FRAME_US: u64 = 10_000;
    /// Wake-up lateness of a frame in thread mode, at most.
    const FRAME_SLACK_US: u64 = 200;
    /// The two timers' counts read together: each read within a count of
    /// its own tick.
    const STEP_US: u64 = 3;
    /// The capture handed to the edge clock this long after it was taken.
    const HANDLER_DELAY_US: u32 = 50;
    const CYCLES_PER_US: u32 = 168;

    /// embassy-time's clock and TIM5's counter, read together.
    fn now() -> (u64, u32) {
        cortex_m::interrupt::free(|_| (Instant::now().as_micros(), pac::TIM5.cnt().read()))
    }

    /// What the frames saw.
    #[derive(Default)]
    struct Watch {
        last: Option<(u64, u32)>,
        /// Each frame's capture, read 50 µs after it.
        edges: EdgeClock,
        /// Each frame's capture, read at the next frame.
        late_edges: EdgeClock,
        frames: u32,
        wraps: u32,
        /// Largest frame step off 10 ms, µs.
        worst_frame_us: u64,
        /// Largest difference between TIM5's and the clock's steps, µs.
        worst_step_us: u64,
        /// Largest error of an edge's date, µs.
        worst_edge_us: u64,
    }

    impl Watch {
        /// One frame's checks.
        fn frame(&mut self) {
            let (t_us, count) = now();
            cortex_m::asm::delay(HANDLER_DELAY_US * CYCLES_PER_US);
            let (later_us, counter) = now();
            let edge = defmt::unwrap!(self.edges.edge_time_us(RawCapture {
                counter,
                capture: count,
                now_us: later_us,
                overcapture: false,
            }));
            self.worst_edge_us = self.worst_edge_us.max(edge.abs_diff(t_us));
            if let Some((t0, c0)) = self.last {
                defmt::assert!(t_us > t0, "the clock went from {} to {} us", t0, t_us);
                // The last frame's capture read now, a frame later: across
                // the wrap at the frame after it.
                let late = defmt::unwrap!(self.late_edges.edge_time_us(RawCapture {
                    counter: count,
                    capture: c0,
                    now_us: t_us,
                    overcapture: false,
                }));
                self.worst_edge_us = self.worst_edge_us.max(late.abs_diff(t0));
                let dt = t_us - t0;
                let dc = u64::from(count.wrapping_sub(c0));
                self.worst_frame_us = self.worst_frame_us.max(dt.abs_diff(FRAME_US));
                self.worst_step_us = self.worst_step_us.max(dc.abs_diff(dt));
                if count < c0 {
                    self.wraps += 1;
                    defmt::info!("TIM5 wrapped between {=u32:x} and {=u32:x}", c0, count);
                }
            }
            self.last = Some((t_us, count));
            self.frames += 1;
        }

        fn assert_held(&self) {
            defmt::info!(
                "{} frames, {} wraps: frame step off 10 ms by {} us at most, TIM5 off the \
                 clock by {} us, edges off by {} us",
                self.frames,
                self.wraps,
                self.worst_frame_us,
                self.worst_step_us,
                self.worst_edge_us
            );
            defmt::assert!(self.worst_frame_us <= FRAME_SLACK_US);
            defmt::assert!(self.worst_step_us <= STEP_US);
            defmt::assert!(self.worst_edge_us <= STEP_US);
            defmt::assert_eq!(self.edges.stats().refused, 0);
            defmt::assert_eq!(self.late_edges.stats().refused, 0);
        }
    }

    #[test]
    async fn the_time_base_stays_in_step_across_the_wrap() {
        let (board, _) = wobble_on_target::board();
        let _timer = wheel::start(board.wheel);
        // 0.5 s before the 32-bit counter wraps.
        pac::TIM5.cnt().write_value(u32::MAX - 500_000);
        let mut watch = Watch::default();
        let mut ticker = Ticker::every(Duration::from_micros(FRAME_US));
        for _ in 0..150 {
            ticker.next().await;
            watch.frame();
        }
        defmt::assert_eq!(watch.wraps, 1);
        defmt::assert!(pac::TIM5.cnt().read() < 1_500_000, "the counter wrapped");
        watch.assert_held();
    }

    /// 75 min of frames from a counter started at 0: one real wrap.
    #[test]
    #[ignore]
    #[timeout(4800)]
    async fn a_soak_across_a_real_wrap_keeps_the_time_base_in_step() {
        let (board, _) = wobble_on_target::board();
        let _timer = wheel::start(board.wheel);
        let mut watch = Watch::default();
        let mut ticker = Ticker::every(Duration::from_micros(FRAME_US));
        let minutes = 75u32;
        for minute in 0..minutes {
            for _ in 0..6000 {
                ticker.next().await;
                watch.frame();
            }
            defmt::info!(
                "minute {} of {}: TIM5 at {=u32:x}, {} wraps",
                minute + 1,
                minutes,
                pac::TIM5.cnt().read(),
                watch.wraps
            );
        }
        defmt::assert_eq!(watch.wraps, 1);
        watch.assert_held();
    }
}
