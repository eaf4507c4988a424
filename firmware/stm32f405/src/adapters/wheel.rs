//! The wheel's hall sensor on TIM5 channel 1: the timer latches the count
//! (1 µs per count) at each falling edge in hardware; a task turns each
//! capture into µs since boot and queues it for the sampler.

use core::sync::atomic::{AtomicU32, Ordering};

use embassy_stm32::pac;
use embassy_stm32::peripherals::TIM5;
use embassy_stm32::timer::input_capture::InputCapture;
use embassy_stm32::timer::Channel as TimerChannel;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_time::Instant;
use wobble_core::app::ports::WheelPort;

/// Edges waiting for the sampler: at 240 edges/s a 10 ms frame sees about
/// 3; 32 covers a sampler 100 ms late.
const EDGE_QUEUE_LEN: usize = 32;

/// Capture task -> sampler.
static EDGES: Channel<CriticalSectionRawMutex, u64, EDGE_QUEUE_LEN> = Channel::new();
/// Edges lost because the sampler did not drain the queue (never expected).
static EDGES_LOST: AtomicU32 = AtomicU32::new(0);

/// Waits for captures for ever (spawned in the high-priority executor, so
/// it runs well within the 4 ms between two edges at 10 m/s).
pub async fn capture_edges(mut capture: InputCapture<'static, TIM5>) -> ! {
    loop {
        // The hall sensor pulls low while a hole passes.
        let latched = capture.wait_for_falling_edge(TimerChannel::Ch1).await;
        // Age of the edge in counts = µs: the counter kept running since
        // the capture. Both clocks derive from the crystal.
        let counter = pac::TIM5.cnt().read();
        let now_us = Instant::now().as_micros();
        let age_us = u64::from(counter.wrapping_sub(latched));
        if EDGES.try_send(now_us.saturating_sub(age_us)).is_err() {
            EDGES_LOST.fetch_add(1, Ordering::Relaxed);
        }
    }
}

/// The sampler's side of the edge queue.
#[derive(Default)]
pub struct WheelAdapter {
    /// Lost edges already reported.
    lost_reported: u32,
}

impl WheelPort for WheelAdapter {
    fn drain_edges(&mut self, edge: &mut dyn FnMut(u64)) {
        while let Ok(t_us) = EDGES.try_receive() {
            edge(t_us);
        }
        let lost = EDGES_LOST.load(Ordering::Relaxed);
        if lost != self.lost_reported {
            defmt::error!("wheel: {} edges lost (queue full)", lost);
            self.lost_reported = lost;
        }
    }
}
