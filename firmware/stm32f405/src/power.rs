//! The power voltage detector (PVD, RM0090 section 5.2.3): an interrupt
//! when VDD falls below 2.9 V and when it comes back, so the writer closes
//! the log while the card still has the supply for its last writes
//! (`wobble_core::app::writer`; SD cards need 2.7 V). The brown-out reset
//! (2.7 V at level 3, programmed by the self-test) comes after it; the
//! board's hold-up (its regulator's output capacitance) decides how many
//! writes fit between the two: an on-target test with a controlled supply
//! measures it (`firmware/docs/board.md`, on-target tests).

use embassy_stm32::interrupt::{self, InterruptExt, Priority};
use embassy_stm32::pac::{EXTI, PWR};
use wobble_core::channels::SharedStatus;

/// PLS = 0b111: the highest threshold, 2.9 V typical on a falling supply
/// (datasheet DS8626, PVD characteristics: 2.76-3.03 V falling).
pub const PLS_2V9: u8 = 0b111;

/// The EXTI line of the PVD output.
const PVD_LINE: usize = 16;

/// Starts the detector on both edges of its output and tells `shared`
/// whether the supply is already low. Call after `embassy_stm32::init`
/// (which clocks the PWR block). The board binary's `PVD` handler calls
/// [`on_interrupt`].
pub fn start(shared: &SharedStatus) {
    PWR.cr1().modify(|w| {
        w.set_pls(PLS_2V9);
        w.set_pvde(true);
    });
    EXTI.rtsr(0).modify(|w| w.set_line(PVD_LINE, true));
    EXTI.ftsr(0).modify(|w| w.set_line(PVD_LINE, true));
    EXTI.pr(0).write(|w| w.set_line(PVD_LINE, true));
    EXTI.imr(0).modify(|w| w.set_line(PVD_LINE, true));
    shared.set_power_low(PWR.csr1().read().pvdo());
    // Below the sampler and the GPS task: it only sets a flag.
    interrupt::PVD.set_priority(Priority::P8);
    // SAFETY: the vector's handler is the binary's, which calls
    // `on_interrupt` and touches nothing else.
    unsafe { interrupt::PVD.enable() };
}

/// The PVD interrupt: clears its EXTI line and tells `shared` whether VDD
/// is below the threshold now (PVDO), whichever edge fired.
pub fn on_interrupt(shared: &SharedStatus) {
    // PR is write-one-to-clear: only line 16 is cleared.
    EXTI.pr(0).write(|w| w.set_line(PVD_LINE, true));
    shared.set_power_low(PWR.csr1().read().pvdo());
}
