//! A debugger's halt stops the logger's clocks with the core: after the
//! logger's own bring-up (`startup::freeze_timers_when_halted`, as `main.rs`
//! calls it, then the watchdog's start through the firmware's feeder),
//! DBGMCU_APB1_FZ holds DBG_TIM3_STOP (embassy-time's driver), DBG_TIM5_STOP
//! (the wheel's and the IMU's capture time base) and DBG_IWDG_STOP.
//!
//! The register survives every reset but a power-on, so a bit another run
//! left set would hide a bring-up that no longer sets it: the test clears
//! the three bits first. What the bits do while the core is halted a test
//! cannot show from inside the halted core: that is bench step 11
//! (`firmware/docs/board.md`): halt the logging board from the probe for
//! 20 s, resume, and the logger goes on without a reset.
//!
//! Run: `cargo test -p wobble-on-target --target thumbv7em-none-eabihf
//! --test debug_freeze` (no wiring).
#![no_std]
#![no_main]

use defmt_rtt as _;

#[cfg(test)]
#[embedded_test::tests]
mod tests {
    use embassy_stm32::pac;
    use embassy_time::Duration;

    /// Whether the three bits are set: (TIM3, TIM5, IWDG).
    fn frozen() -> (bool, bool, bool) {
        let fz = pac::DBGMCU.apb1fzr().read();
        (fz.tim3(), fz.tim5(), fz.iwdg())
    }

    #[test]
    async fn the_time_base_capture_timer_and_watchdog_stop_while_halted() {
        pac::DBGMCU.apb1fzr().modify(|w| {
            w.set_tim3(false);
            w.set_tim5(false);
            w.set_iwdg(false);
        });
        defmt::assert_eq!(frozen(), (false, false, false));
        // The logger's bring-up: clocks, flash accelerator, the freeze.
        let (board, _) = wobble_on_target::board();
        let (tim3, tim5, _) = frozen();
        defmt::assert!(tim3, "TIM3 (embassy-time) runs on while halted");
        defmt::assert!(tim5, "TIM5 (capture time base) runs on while halted");
        // The watchdog's start, fed as the logger feeds it for a while.
        wobble_on_target::feed_watchdog_for(board.watchdog, Duration::from_millis(500)).await;
        defmt::assert_eq!(frozen(), (true, true, true));
        let raw = pac::DBGMCU.apb1fzr().read().0;
        defmt::info!("DBGMCU_APB1_FZ = {=u32:#010x}", raw);
    }
}
