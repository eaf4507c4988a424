//! Two executors on embassy-executor's raw API:
//!
//! - the thread-mode executor idles with WFI. The stock one idles with WFE,
//!   which QEMU emulates as a busy spin; WFI lets `-icount sleep=off` skip
//!   the idle time, so virtual time runs about 10x faster than wall time;
//! - the high-priority executor runs in the PendSV exception, which its
//!   pender pends: a task there preempts thread mode (the SD writer blocked
//!   in a card write) as an interrupt would, without needing a device
//!   interrupt vector.

use core::sync::atomic::{AtomicBool, AtomicPtr, Ordering};

use cortex_m::peripheral::SCB;
use cortex_m_rt::exception;
use embassy_executor::raw;
use embassy_executor::Spawner;
use static_cell::StaticCell;

/// Pender context of the thread executor.
const THREAD: usize = 0;
/// Pender context of the PendSV executor.
const PENDSV: usize = 1;

/// Set when the thread executor has work.
static THREAD_PENDING: AtomicBool = AtomicBool::new(true);
static HIGH: StaticCell<raw::Executor> = StaticCell::new();
/// The PendSV executor once started (the executor is not `Sync`, so the
/// handler finds it through a pointer).
static HIGH_REF: AtomicPtr<raw::Executor> = AtomicPtr::new(core::ptr::null_mut());

#[unsafe(export_name = "__pender")]
fn pender(context: *mut ()) {
    match context as usize {
        PENDSV => SCB::set_pendsv(),
        // Any interrupt ends the WFI; the flag says there is work.
        _ => THREAD_PENDING.store(true, Ordering::Release),
    }
}

/// Starts the PendSV executor with the given NVIC priority and returns its
/// spawner.
pub fn start_high(scb: &mut SCB, priority: u8) -> Spawner {
    let executor: &'static mut raw::Executor = HIGH.init(raw::Executor::new(PENDSV as *mut ()));
    let executor: &'static raw::Executor = executor;
    HIGH_REF.store(core::ptr::from_ref(executor).cast_mut(), Ordering::Release);
    // SAFETY: no task of this executor runs yet.
    unsafe { scb.set_priority(cortex_m::peripheral::scb::SystemHandler::PendSV, priority) };
    executor.spawner()
}

#[exception]
fn PendSV() {
    // SAFETY: the pointer is null or a `&'static` set by `start_high`.
    if let Some(executor) = unsafe { HIGH_REF.load(Ordering::Acquire).as_ref() } {
        // SAFETY: only this handler polls the executor, and it does not
        // reenter itself.
        unsafe { executor.poll() };
    }
}

/// Runs the thread-mode executor for ever, sleeping in WFI when idle.
pub fn run_thread(init: impl FnOnce(Spawner)) -> ! {
    static THREAD_EXEC: StaticCell<raw::Executor> = StaticCell::new();
    let executor: &'static raw::Executor = THREAD_EXEC.init(raw::Executor::new(THREAD as *mut ()));
    init(executor.spawner());
    loop {
        if THREAD_PENDING.swap(false, Ordering::AcqRel) {
            // SAFETY: only this loop polls the thread executor.
            unsafe { executor.poll() };
            continue;
        }
        // With interrupts masked, one arriving after the check stays
        // pending and ends the WFI at once instead of being missed.
        cortex_m::interrupt::disable();
        if !THREAD_PENDING.load(Ordering::Acquire) {
            cortex_m::asm::wfi();
        }
        // SAFETY: interrupts were enabled before this point.
        unsafe { cortex_m::interrupt::enable() };
    }
}
