//! The independent watchdog, fed only while every task shows progress.
//!
//! The sampler (high priority) and the GPS task (medium priority) count
//! heartbeats; the thread-mode writer proves itself by asking for a feed:
//! after every card operation (`adapters::card`) and from a task that runs
//! only when the writer yields. A feed happens at most once a round and
//! only if both heartbeats moved (the core's `watchdog::Liveness`); the
//! timeout is sized there for the slowest card operation and the LSI's
//! full 17-47 kHz range.

use core::cell::RefCell;
use core::sync::atomic::{AtomicU32, Ordering};

use embassy_stm32::peripherals::IWDG;
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_stm32::Peri;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::blocking_mutex::Mutex;
use embassy_time::{Instant, Timer};
use wobble_core::boot::PANIC_STREAK_CLEAR_US;
use wobble_core::channels::{RecordQueue, SharedStatus, QUEUE_LEN};
use wobble_core::watchdog::{Liveness, Verdict, TIMEOUT_REQUEST_US};

/// How often the task behind the writer asks.
const ASK_MS: u64 = 250;
/// Asks between two stack reports: a minute.
const STACK_REPORT_ASKS: u32 = 240;

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

struct Dog {
    iwdg: Option<IndependentWatchdog<'static, IWDG>>,
    liveness: Liveness<2>,
}

static DOG: Mutex<CriticalSectionRawMutex, RefCell<Dog>> = Mutex::new(RefCell::new(Dog {
    iwdg: None,
    liveness: Liveness::new(),
}));

/// Feeds the watchdog if a round is due and every heartbeat moved (thread
/// mode: the writer's side). Does nothing before [`feed`] started it.
pub fn prove_alive() {
    DOG.lock(|dog| {
        let mut dog = dog.borrow_mut();
        let beats = [SAMPLER.count(), GPS.count()];
        match dog.liveness.check(Instant::now().as_micros(), beats) {
            Verdict::NotDue => {}
            Verdict::Alive => {
                if let Some(iwdg) = dog.iwdg.as_mut() {
                    iwdg.pet();
                }
            }
            Verdict::Stalled(task) => {
                defmt::error!("watchdog: task {} (0 sampler, 1 gps) stopped", task);
            }
        }
    });
}

/// Starts the watchdog and asks for feeds behind the writer; once a minute
/// logs the stack's, the record queue's and the writer's worst figures.
pub async fn feed(
    iwdg: Peri<'static, IWDG>,
    queue: &'static RecordQueue,
    shared: &'static SharedStatus,
) -> ! {
    // A breakpoint would otherwise reset the MCU under the probe after
    // 3-8 s: the watchdog stops with the core, whoever brought the chip up.
    crate::startup::freeze_timers_when_halted();
    let mut dog = IndependentWatchdog::new(iwdg, TIMEOUT_REQUEST_US as u32);
    dog.unleash();
    DOG.lock(|d| {
        let mut d = d.borrow_mut();
        d.iwdg = Some(dog);
        // Rounds count from here: before, the card reads at boot (and the
        // self-test, which never starts the watchdog) ask with nothing due.
        let beats = [SAMPLER.count(), GPS.count()];
        d.liveness.arm(Instant::now().as_micros(), beats);
    });
    let mut asks = 0u32;
    loop {
        prove_alive();
        // The stack's high-water mark in the log once a minute (a scan of
        // the painted stack, well under a millisecond), with the queue's
        // and the writer's worst iterations (`app::writer`).
        if asks.is_multiple_of(STACK_REPORT_ASKS) {
            let (used, size) = crate::startup::stack_use();
            defmt::info!("stack: {} of {} bytes used at most", used, size);
            let writer = shared.writer();
            defmt::info!(
                "queue: high water {} of {} records, {} frames dropped and not yet in a \
                 dropout record, {} other records dropped; writer: at most {} card operations in an iteration while logging ({} opening \
                 a card), longest iteration {} us",
                queue.high_water(),
                QUEUE_LEN,
                queue.frames_dropped_pending(),
                queue.others_dropped(),
                writer.ops_max,
                writer.open_ops_max,
                writer.busy_max_us
            );
        }
        asks = asks.wrapping_add(1);
        if u64::from(asks) * ASK_MS * 1000 == PANIC_STREAK_CLEAR_US {
            crate::startup::clear_panic_streak();
        }
        Timer::after_millis(ASK_MS).await;
    }
}
