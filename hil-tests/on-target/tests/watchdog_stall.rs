//! A stalled task makes the independent watchdog reset the chip: the
//! firmware's own feeder runs while both heartbeats move, then the GPS
//! heartbeat stops (the sampler's keeps going) and the test waits for the
//! reset. It passes only after a reset whose cause is the IWDG, which the
//! chip reports in RCC_CSR on the next boot.
//!
//! A test that spans a reset needs two things the harness does not give:
//! - memory that survives it: a record in `.uninit` RAM (not zeroed by
//!   cortex-m-rt at reset; SRAM keeps its contents through a system
//!   reset), told from the noise after a power-on by a magic word;
//! - a way to report after it. probe-rs's embedded-test runner (0.32,
//!   `rpc/functions/test.rs`) resets the board, answers the first
//!   SYS_GET_CMDLINE with the test to run, then waits for SYS_EXIT; it
//!   enables the reset vector catch and takes any halt other than
//!   semihosting as a failure of the whole run, and a second
//!   SYS_GET_CMDLINE as an error. So the test clears the reset vector catch
//!   (DEMCR.VC_CORERESET, which a system reset leaves as it is) before the
//!   stall, and after the reset this binary's setup function, which
//!   embedded-test 0.7 runs before it asks for the command line, finds the
//!   record and ends the test itself with SYS_EXIT (exit 0: pass). The RTT
//!   log survives: probe-rs re-attaches when the rebooted chip rewinds the
//!   buffer's pointers.
//!
//! Run: `cargo test -p wobble-on-target --target thumbv7em-none-eabihf
//! --test watchdog_stall` (no wiring). It takes 5.4 s fed, then the
//! watchdog's 3-8.3 s (it fails after 10.3 s without a reset).
#![no_std]
#![no_main]

use core::mem::MaybeUninit;
use core::ptr::addr_of_mut;

use defmt_rtt as _;
use wobble_core::boot::ResetCause;
use wobble_stm32f405::startup;

/// Tells a record written by this test from RAM noise after a power-on.
const MAGIC: u32 = 0x5741_4444;
/// The watchdog runs and both tasks beat: a reset now is a failure.
const FED: u32 = 1;
/// The GPS heartbeat has stopped: the reset is what the test waits for.
const STALLED: u32 = 2;

/// The stage the test reached, kept across the reset.
#[link_section = ".uninit.WATCHDOG_STALL"]
static mut STAGE: MaybeUninit<[u32; 2]> = MaybeUninit::uninit();

fn set_stage(stage: u32) {
    // SAFETY: only this test's single thread touches STAGE.
    unsafe { addr_of_mut!(STAGE).write_volatile(MaybeUninit::new([MAGIC, stage])) }
}

/// The stage the previous boot left, once: it is cleared as it is read.
fn take_stage() -> Option<u32> {
    // SAFETY: as in `set_stage`; any bit pattern is a valid `[u32; 2]`.
    let [magic, stage] = unsafe { addr_of_mut!(STAGE).read_volatile().assume_init() };
    set_stage(0);
    (magic == MAGIC).then_some(stage)
}

/// Runs at every boot before embedded-test asks for the test to run.
#[embedded_test::setup]
fn after_the_reset() {
    match take_stage() {
        Some(STALLED) => {
            let cause = startup::take_reset_cause();
            if cause == ResetCause::Watchdog {
                defmt::info!("reset after the stall, cause {}: pass", cause);
                semihosting::process::exit(0);
            }
            // A probe reset after an interrupted run also lands here: go
            // on as usual (a reset in a running test makes probe-rs fail
            // it at the next SYS_GET_CMDLINE anyway).
            defmt::warn!("a stall record, but reset cause {}", cause);
        }
        Some(FED) => {
            defmt::error!("reset while the watchdog was fed and both tasks beat");
            semihosting::process::abort();
        }
        _ => {}
    }
}

#[cfg(test)]
#[embedded_test::tests]
mod tests {
    use embassy_futures::select::{select, Either};
    use embassy_time::{Duration, Instant, Timer};
    use wobble_core::channels::SharedStatus;
    use wobble_core::watchdog::TIMEOUT_REQUEST_US;
    use wobble_stm32f405::watchdog;

    use super::{set_stage, FED, STALLED};

    /// DEMCR.VC_CORERESET (ARMv7-M ARM C1.6.5): halt at the reset vector.
    const VC_CORERESET: u32 = 1;
    /// The LSI the watchdog driver assumes, and the slowest the datasheet
    /// allows: the timeout stretches by their ratio.
    const LSI_ASSUMED_HZ: u64 = 32_000;
    const LSI_SLOWEST_HZ: u64 = 17_000;
    /// A feed may still come up to a round (1 s) after the stall, as the
    /// round that saw the last beats ends; and a margin.
    const ROUND_AND_MARGIN_US: u64 = 2_000_000;

    #[test]
    #[timeout(40)]
    async fn a_stalled_task_makes_the_watchdog_reset_the_chip() {
        let (board, _) = wobble_on_target::board();
        // The feeder logs the queue's figures with the stack's once a minute.
        static SHARED: SharedStatus = SharedStatus::new();
        let queue = defmt::unwrap!(wobble_stm32f405::ccm::record_queue());
        // SAFETY: clearing the reset vector catch only changes what a
        // debugger does at the next reset (module docs).
        unsafe {
            (*cortex_m::peripheral::DCB::PTR)
                .demcr
                .modify(|w| w & !VC_CORERESET);
        }
        // Fed for longer than the shortest timeout (3 s at the fastest
        // LSI): a feeder that did not feed would reset the chip here.
        let fed_for = Duration::from_micros(TIMEOUT_REQUEST_US + 1_000_000);
        // After the stall, the longest the reset may take.
        let wait_for = Duration::from_micros(
            TIMEOUT_REQUEST_US * LSI_ASSUMED_HZ / LSI_SLOWEST_HZ + ROUND_AND_MARGIN_US,
        );
        let start = Instant::now();
        set_stage(FED);
        let heartbeats = async {
            while Instant::now() - start < fed_for {
                watchdog::SAMPLER.beat();
                watchdog::GPS.beat();
                Timer::after_millis(10).await;
            }
            set_stage(STALLED);
            defmt::info!(
                "GPS heartbeat stopped: expecting a reset within {} ms",
                wait_for.as_millis()
            );
            let stalled = Instant::now();
            while Instant::now() - stalled < wait_for {
                watchdog::SAMPLER.beat();
                Timer::after_millis(10).await;
            }
        };
        match select(watchdog::feed(board.watchdog, queue, &SHARED), heartbeats).await {
            Either::First(never) => match never {},
            Either::Second(()) => {}
        }
        defmt::panic!(
            "no reset {} ms after the GPS task stalled",
            wait_for.as_millis()
        );
    }
}
