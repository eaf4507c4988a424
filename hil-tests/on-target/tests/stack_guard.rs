//! A stack overflow runs into the firmware's MPU stack guard
//! (`startup::guard_stack`: 256 no-access bytes at the bottom of the stack,
//! right above the statics) and ends in a reset the next boot can tell,
//! instead of silently overwriting the statics below.
//!
//! The test sets the guard as `main.rs` does, then recurses without end in
//! frames well under the guard's 256 bytes, noting in `.uninit` RAM the
//! lowest stack pointer each level reached, beside a canary. The first
//! store into the guard faults. The MemManage fault is not enabled on its
//! own, so it escalates to HardFault; what follows is one of the two ends
//! `startup.rs` documents:
//! - the hard fault handler runs (`startup::HardFault`): it marks the
//!   coming reset as the firmware's own fault (`boot::FAULT_RESET_MARK`, the
//!   next boot's panic streak counts it) and resets: a software reset;
//! - or the exception's own stacking, below the faulting stack pointer,
//!   hits the guard too, the core locks up, and the watchdog (started here
//!   as the logger has it running) resets it: a watchdog reset, which the
//!   streak counts as well.
//!
//! After the reset this binary's setup function (embedded-test 0.7 runs it
//! before asking for the test to run) finds the record and passes when the
//! reset is one of the two, the fault mark or the watchdog shows it was
//! counted (streak 1), the recursion got down to the guard and no lower,
//! and the canary in the statics below the stack is whole. It then ends the
//! test over semihosting, as `watchdog_stall` does (its module docs say why
//! probe-rs's runner needs that); the debugger's vector catches (reset,
//! hard fault, fault on exception entry) are cleared before the overflow,
//! so probe-rs does not halt the chip at the fault or the reset.
//!
//! Run: `cargo test -p wobble-on-target --target thumbv7em-none-eabihf
//! --test stack_guard` (no wiring). It takes well under 2 s.
#![no_std]
#![no_main]

use core::mem::MaybeUninit;
use core::ptr::addr_of_mut;

use defmt_rtt as _;
use wobble_core::boot::ResetCause;
use wobble_stm32f405::startup;

/// Tells a record written by this test from RAM noise after a power-on.
const MAGIC: u32 = 0x5753_4F56;
/// The recursion has begun: a reset now is what the test waits for.
const DIVING: u32 = 1;
/// A word pattern no stack frame of the recursion holds.
const CANARY: u32 = 0xC0DE_CAFE;
const CANARY_WORDS: usize = 16;

/// The record kept across the reset: magic, stage, the lowest stack
/// pointer reached, the depth, then the canary. In `.uninit`, the statics'
/// last section, which the stack meets first when it overflows.
#[link_section = ".uninit.STACK_GUARD"]
static mut RECORD: MaybeUninit<[u32; 4 + CANARY_WORDS]> = MaybeUninit::uninit();

fn record() -> *mut u32 {
    addr_of_mut!(RECORD).cast::<u32>()
}

fn write_word(i: usize, value: u32) {
    // SAFETY: `i` is within the record (callers pass constants below its
    // length); only this test's thread touches it, volatile so every
    // level's note is stored before the next level can fault.
    unsafe { record().add(i).write_volatile(value) }
}

fn read_word(i: usize) -> u32 {
    // SAFETY: as in `write_word`; any bit pattern is a valid `u32`.
    unsafe { record().add(i).read_volatile() }
}

/// One level more, noting the stack pointer and depth first. The frame is
/// a few dozen bytes (a 32-byte array kept in memory by `black_box`), far
/// under the guard's 256, so no frame can step over the guard.
#[inline(never)]
fn dive(depth: u32) -> u32 {
    let mut frame = [depth; 8];
    core::hint::black_box(&mut frame);
    let sp = cortex_m::register::msp::read();
    if sp < read_word(2) {
        write_word(2, sp);
    }
    write_word(3, depth);
    if depth == u32::MAX {
        return frame[1];
    }
    // Not a tail call: the frame lives on after the call returns.
    dive(depth + 1).wrapping_add(core::hint::black_box(frame)[7])
}

/// Runs at every boot before embedded-test asks for the test to run.
#[embedded_test::setup]
fn after_the_reset() {
    if read_word(0) != MAGIC || read_word(1) != DIVING {
        return;
    }
    write_word(1, 0);
    let cause = startup::take_reset_cause();
    let (streak, _) = startup::take_panic_streak(cause);
    let (guard_base, guard_end) = startup::guard_region();
    let lowest = read_word(2);
    let depth = read_word(3);
    let canary_whole = (0..CANARY_WORDS).all(|i| read_word(4 + i) == CANARY);
    defmt::info!(
        "reset after the overflow: cause {}, streak {}, {} levels deep, lowest stack \
         pointer {=u32:#x}, guard {=u32:#x}..{=u32:#x}, canary {}",
        cause,
        streak,
        depth,
        lowest,
        guard_base,
        guard_end,
        if canary_whole { "whole" } else { "overwritten" }
    );
    let counted = match cause {
        // The hard fault handler's own reset, marked for the streak.
        ResetCause::Software => streak == 1,
        // A lockup, ended by the watchdog.
        ResetCause::Watchdog => streak == 1,
        _ => false,
    };
    // The deepest frame noted sits just above the guard: the next one's
    // first store faulted. 256 bytes is far more than one frame.
    let stopped_at_guard = lowest >= guard_end && lowest < guard_end + 256;
    if counted && stopped_at_guard && canary_whole {
        semihosting::process::exit(0);
    }
    defmt::error!(
        "counted as a fault reset: {}, stopped at the guard: {}, canary whole: {}",
        counted,
        stopped_at_guard,
        canary_whole
    );
    semihosting::process::abort();
}

#[cfg(test)]
#[embedded_test::tests]
mod tests {
    use embassy_stm32::wdg::IndependentWatchdog;
    use wobble_stm32f405::startup;

    use super::{dive, write_word, CANARY, CANARY_WORDS, DIVING, MAGIC};

    /// DEMCR (ARMv7-M ARM C1.6.5) vector catches: VC_CORERESET (bit 0),
    /// VC_MMERR (4), VC_BUSERR (8), VC_INTERR (9, a fault on exception
    /// entry), VC_HARDERR (10).
    const VECTOR_CATCHES: u32 = 1 | (1 << 4) | (1 << 8) | (1 << 9) | (1 << 10);
    /// The watchdog's timeout for a lockup, µs.
    const WATCHDOG_US: u32 = 1_000_000;

    #[test]
    #[timeout(10)]
    fn a_stack_overflow_hits_the_guard_and_resets_the_chip() {
        let (board, _) = wobble_on_target::board();
        // Clear what an earlier run left, then start the record.
        let _ = startup::take_reset_cause();
        startup::clear_panic_streak();
        startup::guard_stack();
        let mut dog = IndependentWatchdog::new(board.watchdog, WATCHDOG_US);
        dog.unleash();
        dog.pet();
        write_word(0, MAGIC);
        write_word(2, u32::MAX);
        write_word(3, 0);
        for i in 0..CANARY_WORDS {
            write_word(4 + i, CANARY);
        }
        // SAFETY: clearing vector catches only changes what a debugger does
        // at the next fault or reset (module docs).
        unsafe {
            (*cortex_m::peripheral::DCB::PTR)
                .demcr
                .modify(|w| w & !VECTOR_CATCHES);
        }
        defmt::info!("diving: expecting a reset");
        write_word(1, DIVING);
        let never = dive(0);
        write_word(1, 0);
        defmt::panic!("the recursion returned {}: no fault", never);
    }
}
