//! The independent watchdog, fed only while every task shows progress.
//!
//! The feeding task runs in thread mode, behind the SD writer: if the
//! writer hangs, the feeder never runs. The sampler (high priority) and the
//! GPS task (medium priority) count heartbeats; the feeder checks that both
//! moved since its last round.

use core::sync::atomic::{AtomicU32, Ordering};

use embassy_stm32::peripherals::IWDG;
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_stm32::Peri;
use embassy_time::Timer;

/// Reset after this long without feeding: above the longest legitimate
/// block of thread mode (a missing card's acquisition, about 0.7 s, or a
/// card's 0.5 s write stall) with margin.
pub const TIMEOUT_US: u32 = 4_000_000;
/// One round of checks.
const ROUND_MS: u64 = 1_000;

/// A task's heartbeat counter.
pub struct Heartbeat(AtomicU32);

impl Heartbeat {
    const fn new() -> Self {
        Self(AtomicU32::new(0))
    }

    /// The task made progress.
    pub fn beat(&self) {
        self.0.fetch_add(1, Ordering::Relaxed);
    }

    fn count(&self) -> u32 {
        self.0.load(Ordering::Relaxed)
    }
}

/// Beats once per 100 Hz frame.
pub static SAMPLER: Heartbeat = Heartbeat::new();
/// Beats at least every 100 ms (each wait for GPS bytes).
pub static GPS: Heartbeat = Heartbeat::new();

/// Starts the watchdog and feeds it while the heartbeats move.
pub async fn feed(iwdg: Peri<'static, IWDG>) -> ! {
    let mut dog = IndependentWatchdog::new(iwdg, TIMEOUT_US);
    dog.unleash();
    let mut last = [SAMPLER.count(), GPS.count()];
    loop {
        Timer::after_millis(ROUND_MS).await;
        let now = [SAMPLER.count(), GPS.count()];
        if now.iter().zip(last).all(|(&n, l)| n != l) {
            dog.pet();
        } else {
            defmt::error!("watchdog: a task stopped (sampler, gps beats {})", now);
        }
        last = now;
    }
}
