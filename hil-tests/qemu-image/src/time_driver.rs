//! embassy-time driver on SysTick: QEMU's netduinoplus2 emulates neither the
//! RCC well enough for embassy-stm32 nor its TIM2 time driver, but its
//! SysTick counts the 168 MHz core clock whatever RCC says.
//!
//! SysTick interrupts every 1 ms (168 000 cycles: reload 167 999); `now()`
//! adds the counter's progress within the millisecond, so time stamps have
//! 1 µs resolution while alarms fire on the next millisecond tick. The
//! 100 Hz sampler's deadlines fall on whole milliseconds anyway.

use core::cell::{Cell, RefCell};
use core::sync::atomic::{AtomicU32, Ordering};
use core::task::Waker;

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::{SCB, SYST};
use cortex_m_rt::exception;
use critical_section::Mutex;
use embassy_time_driver::Driver;
use embassy_time_queue_utils::Queue;

/// Core clock, Hz.
const CORE_HZ: u32 = 168_000_000;
/// SysTick period: 1 ms.
const CYCLES_PER_MS: u32 = CORE_HZ / 1000;
const CYCLES_PER_US: u32 = CORE_HZ / 1_000_000;

struct SysTickDriver {
    /// Milliseconds since start (wraps after 49 days; a ride is shorter).
    ms: AtomicU32,
    /// Timer queue and the next time it needs attention, µs.
    queue: Mutex<RefCell<Queue>>,
    next_alarm_us: Mutex<Cell<u64>>,
}

embassy_time_driver::time_driver_impl!(static DRIVER: SysTickDriver = SysTickDriver {
    ms: AtomicU32::new(0),
    queue: Mutex::new(RefCell::new(Queue::new())),
    next_alarm_us: Mutex::new(Cell::new(u64::MAX)),
});

/// Starts SysTick at 1 kHz with the given NVIC priority; takes `SYST` so
/// nothing else can reprogram it.
pub fn init(mut syst: SYST, scb: &mut SCB, priority: u8) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(CYCLES_PER_MS - 1);
    syst.clear_current();
    // SAFETY: setting a priority cannot break a critical section here: no
    // task runs yet.
    unsafe { scb.set_priority(cortex_m::peripheral::scb::SystemHandler::SysTick, priority) };
    syst.enable_interrupt();
    syst.enable_counter();
}

impl SysTickDriver {
    /// Core clock cycles since start (SysTick's count: under QEMU's
    /// instruction clock, virtual time at 168 MHz).
    fn cycles(&self) -> u64 {
        loop {
            let ms = self.ms.load(Ordering::Acquire);
            let pending = SCB::is_pendst_pending();
            let cvr = SYST::get_current();
            // A wrap between the reads shows as a changed pending bit or ms.
            if ms == self.ms.load(Ordering::Acquire) && pending == SCB::is_pendst_pending() {
                let ms = u64::from(ms) + u64::from(pending);
                return ms * u64::from(CYCLES_PER_MS) + u64::from(CYCLES_PER_MS - 1 - cvr);
            }
        }
    }
}

/// Virtual time since start, ns (at 168 MHz: a resolution of 6 ns, finer
/// than QEMU's 8 ns per instruction; `Instant` counts whole µs).
pub fn now_ns() -> u64 {
    DRIVER.cycles() * 1000 / u64::from(CYCLES_PER_US)
}

impl Driver for SysTickDriver {
    fn now(&self) -> u64 {
        self.cycles() / u64::from(CYCLES_PER_US)
    }

    fn schedule_wake(&self, at: u64, waker: &Waker) {
        critical_section::with(|cs| {
            let mut queue = self.queue.borrow_ref_mut(cs);
            if queue.schedule_wake(at, waker) {
                let next = self.next_alarm_us.borrow(cs);
                next.set(next.get().min(at));
            }
        });
    }
}

#[exception]
fn SysTick() {
    DRIVER.ms.fetch_add(1, Ordering::AcqRel);
    let now = DRIVER.now();
    critical_section::with(|cs| {
        let next = DRIVER.next_alarm_us.borrow(cs);
        if now >= next.get() {
            next.set(DRIVER.queue.borrow_ref_mut(cs).next_expiration(now));
        }
    });
}
