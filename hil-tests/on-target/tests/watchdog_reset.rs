//! The watchdog and the reset cause on the real chip: the RCC_CSR flags
//! decode to the reset the probe gave and are cleared once read, and the
//! independent watchdog, fed by the firmware's own feeder while both
//! heartbeats move, lets the chip run for three times its timeout.
#![no_std]
#![no_main]

use defmt_rtt as _;

#[cfg(test)]
#[embedded_test::tests]
mod tests {
    use embassy_stm32::pac;
    use embassy_time::{Duration, Instant};
    use wobble_core::boot::ResetCause;
    use wobble_core::watchdog::TIMEOUT_REQUEST_US;
    use wobble_stm32f405::startup;

    /// RCC_CSR bits 24-31: the reset flags (RM0090 7.3.21).
    const RESET_FLAGS: u32 = 0xFF00_0000;

    #[test]
    fn the_reset_cause_is_the_probes_and_is_cleared_once_read() {
        let (_board, _) = wobble_on_target::board();
        let cause = startup::take_reset_cause();
        defmt::info!("reset cause: {}", cause);
        // probe-rs resets through SYSRESETREQ (software) or NRST (pin); a
        // first run after switching on sees the power-on reset.
        defmt::assert!(
            matches!(
                cause,
                ResetCause::Software | ResetCause::Pin | ResetCause::PowerOn
            ),
            "reset cause {}",
            cause
        );
        defmt::assert_eq!(pac::RCC.csr().read().0 & RESET_FLAGS, 0);
        defmt::assert_eq!(startup::take_reset_cause(), ResetCause::Unknown);
    }

    #[test]
    async fn a_fed_watchdog_lets_the_chip_run_past_its_timeout() {
        let (board, _) = wobble_on_target::board();
        let run_for = Duration::from_micros(3 * TIMEOUT_REQUEST_US);
        let start = Instant::now();
        // A reset here fails the test: probe-rs loses the running test.
        wobble_on_target::feed_watchdog_for(board.watchdog, run_for).await;
        defmt::info!(
            "ran {} ms under the watchdog",
            (Instant::now() - start).as_millis()
        );
    }
}
