//! CPU-only state in the core-coupled RAM (CCM, 64 KiB at 0x1000_0000):
//! the record queue between the sampler, the GPS task and the SD writer
//! (`wobble_core::channels::RecordQueue`, 576 records of 64 bytes, 36 KiB).
//!
//! CCM sits on the CPU's data bus alone: the DMA controllers cannot reach
//! it, so no DMA buffer may ever live here (the SPI, ADC and USART rings
//! stay in SRAM). The queue only moves records between tasks by CPU
//! copies, which makes it the largest piece of state that can go.
//!
//! The section (`.ccmram` in `memory.x`) is NOLOAD, and cortex-m-rt's reset
//! code initialises only `.data` and `.bss`: what is here holds whatever
//! the RAM held at reset. So the static is a `MaybeUninit`, which the
//! compiler never assumes to hold a value, and [`record_queue`] writes an
//! empty queue into it before handing out the only reference.

use core::mem::MaybeUninit;
use core::sync::atomic::{AtomicBool, Ordering};

use wobble_core::channels::RecordQueue;

/// The queue's storage in CCM; written once by [`record_queue`].
#[link_section = ".ccmram.record_queue"]
static mut QUEUE: MaybeUninit<RecordQueue> = MaybeUninit::uninit();
/// Whether [`record_queue`] ran (in `.bss`: zero at reset).
static TAKEN: AtomicBool = AtomicBool::new(false);

/// The record queue, empty, in CCM: the first call initialises it and
/// returns it; any later call returns `None` (one queue per boot).
pub fn record_queue() -> Option<&'static RecordQueue> {
    if TAKEN.swap(true, Ordering::AcqRel) {
        return None;
    }
    // SAFETY: the flag makes this the only access to QUEUE ever: no other
    // reference to it exists, and the one returned is shared from here on.
    let slot = unsafe { &mut *core::ptr::addr_of_mut!(QUEUE) };
    Some(init(slot))
}

/// Writes an empty queue into `slot`, in place: `RecordQueue::new` is a
/// constant whose buffer is uninitialised, so the write stores the
/// queue's few bookkeeping words, not 36 KiB through the stack (the
/// stack bound, `firmware/docs/board.md`, measures this frame).
#[inline(never)]
fn init(slot: &'static mut MaybeUninit<RecordQueue>) -> &'static RecordQueue {
    slot.write(RecordQueue::new())
}
