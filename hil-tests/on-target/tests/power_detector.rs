//! The power voltage detector on the real chip: `power::start` sets the
//! 2.9 V level and both edges of EXTI line 16, a bench supply at 3.3 V
//! reads as not low, and the interrupt (raised here by software) reaches
//! the handler, which clears its line and reports the supply as the PVD
//! output says. Lowering the supply itself is bench step 5a
//! (`firmware/docs/board.md`).
#![no_std]
#![no_main]

use defmt_rtt as _;
use embassy_stm32::interrupt;
use wobble_core::channels::SharedStatus;
use wobble_stm32f405::power;

static SHARED: SharedStatus = SharedStatus::new();
static HANDLED: core::sync::atomic::AtomicU32 = core::sync::atomic::AtomicU32::new(0);

#[interrupt]
fn PVD() {
    power::on_interrupt(&SHARED);
    HANDLED.fetch_add(1, core::sync::atomic::Ordering::Relaxed);
}

#[cfg(test)]
#[embedded_test::tests]
mod tests {
    use core::sync::atomic::Ordering;

    use embassy_stm32::pac::{EXTI, PWR};
    use embassy_time::Timer;
    use wobble_stm32f405::power;

    const LINE: usize = 16;

    #[test]
    async fn the_detector_watches_2v9_on_both_edges_and_its_interrupt_is_handled() {
        let (_board, _) = wobble_on_target::board();
        power::start(&super::SHARED);
        let cr = PWR.cr1().read();
        defmt::assert!(cr.pvde());
        defmt::assert_eq!(cr.pls(), power::PLS_2V9);
        defmt::assert!(EXTI.imr(0).read().line(LINE));
        defmt::assert!(EXTI.rtsr(0).read().line(LINE));
        defmt::assert!(EXTI.ftsr(0).read().line(LINE));
        // A bench supply at 3.3 V is above the threshold.
        defmt::assert!(!PWR.csr1().read().pvdo());
        defmt::assert!(!super::SHARED.power_low());
        // The line raised by software: the handler runs once and clears it.
        EXTI.swier(0).write(|w| w.set_line(LINE, true));
        Timer::after_millis(1).await;
        defmt::assert_eq!(super::HANDLED.load(Ordering::Relaxed), 1);
        defmt::assert!(!EXTI.pr(0).read().line(LINE));
        defmt::assert!(!super::SHARED.power_low());
        defmt::assert_eq!(super::SHARED.power_falls(), 0);
    }
}
