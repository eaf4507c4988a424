//! The board's three executors on embassy-executor's raw API:
//!
//! - the thread-mode executor idles with WFI. The stock one idles with WFE,
//!   which QEMU emulates as a busy spin; WFI lets `-icount sleep=off` skip
//!   the idle time, so virtual time runs about 10x faster than wall time;
//! - the high-priority executor (the sampler) runs in the PendSV exception;
//! - the medium-priority executor (GPS) runs in a spare NVIC interrupt,
//!   UART5's vector as on the board (QEMU's UART5 stays disabled, so only
//!   the pender raises it). Without a device crate every NVIC vector is
//!   cortex-m-rt's `DefaultHandler`, which dispatches on the number.
//!
//! Each interrupt executor preempts what runs below it (the SD writer
//! blocked in a card write, the GPS task parsing a sentence) as the board's
//! `InterruptExecutor`s do. Those need embassy-executor's cortex-m platform,
//! whose thread executor and pender would replace the WFI one here.

use core::sync::atomic::{AtomicBool, AtomicPtr, Ordering};

use cortex_m::interrupt::InterruptNumber;
use cortex_m::peripheral::{NVIC, SCB};
use cortex_m_rt::exception;
use embassy_executor::raw;
use embassy_executor::Spawner;
use static_cell::StaticCell;

/// Pender context of the thread executor.
const THREAD: usize = 0;
/// Pender context of the PendSV executor.
const PENDSV: usize = 1;
/// Pender context of the medium executor.
const MEDIUM: usize = 2;

/// The medium executor's interrupt: UART5 on the STM32F405.
#[derive(Clone, Copy)]
struct MediumIrq;

// SAFETY: 53 is UART5's position in the STM32F405's vector table.
unsafe impl InterruptNumber for MediumIrq {
    fn number(self) -> u16 {
        53
    }
}

/// Set when the thread executor has work.
static THREAD_PENDING: AtomicBool = AtomicBool::new(true);

/// An executor run from an interrupt handler (the executor is not `Sync`,
/// so the handler finds it through a pointer).
struct InterruptSlot {
    cell: StaticCell<raw::Executor>,
    running: AtomicPtr<raw::Executor>,
}

impl InterruptSlot {
    const fn new() -> Self {
        Self {
            cell: StaticCell::new(),
            running: AtomicPtr::new(core::ptr::null_mut()),
        }
    }

    fn start(&'static self, context: usize) -> Spawner {
        let executor: &'static raw::Executor =
            self.cell.init(raw::Executor::new(context as *mut ()));
        self.running
            .store(core::ptr::from_ref(executor).cast_mut(), Ordering::Release);
        executor.spawner()
    }

    fn poll(&self) {
        // SAFETY: the pointer is null or a `&'static` set by `start`.
        if let Some(executor) = unsafe { self.running.load(Ordering::Acquire).as_ref() } {
            // SAFETY: only this slot's handler polls the executor, and it
            // does not reenter itself.
            unsafe { executor.poll() };
        }
    }
}

static HIGH: InterruptSlot = InterruptSlot::new();
static MEDIUM_SLOT: InterruptSlot = InterruptSlot::new();

#[unsafe(export_name = "__pender")]
fn pender(context: *mut ()) {
    match context as usize {
        PENDSV => SCB::set_pendsv(),
        MEDIUM => NVIC::pend(MediumIrq),
        // Any interrupt ends the WFI; the flag says there is work.
        _ => THREAD_PENDING.store(true, Ordering::Release),
    }
}

/// Starts the PendSV executor with the given NVIC priority and returns its
/// spawner.
pub fn start_high(scb: &mut SCB, priority: u8) -> Spawner {
    let spawner = HIGH.start(PENDSV);
    // SAFETY: no task of this executor runs yet.
    unsafe { scb.set_priority(cortex_m::peripheral::scb::SystemHandler::PendSV, priority) };
    spawner
}

/// Starts the medium executor in its interrupt with the given NVIC
/// priority and returns its spawner.
pub fn start_medium(nvic: &mut NVIC, priority: u8) -> Spawner {
    let spawner = MEDIUM_SLOT.start(MEDIUM);
    // SAFETY: no task of this executor runs yet, and its handler only polls
    // it.
    unsafe {
        nvic.set_priority(MediumIrq, priority);
        NVIC::unmask(MediumIrq);
    }
    spawner
}

#[exception]
fn PendSV() {
    HIGH.poll();
}

#[exception]
unsafe fn DefaultHandler(irqn: i16) {
    if irqn == MediumIrq.number() as i16 {
        MEDIUM_SLOT.poll();
    } else {
        crate::report::line(format_args!("FATAL unexpected interrupt {irqn}"));
        semihosting::process::exit(2)
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
