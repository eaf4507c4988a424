//! Register work before and right after `embassy_stm32::init`: the reset
//! cause, a bounded wait for the crystal, the flash accelerator, the
//! brown-out level, and a visible failure code. The decisions (what the
//! flags mean, which option word to program, which fault to record) are the
//! core's `boot` module.

use cortex_m_rt::{exception, ExceptionFrame};
use embassy_stm32::gpio::Output;
use embassy_stm32::pac::{self, FLASH, RCC};
use embassy_time::{block_for, Duration};
use wobble_core::boot::{
    optcr_with_bor_level3, BorLevel, ResetCause, FAULT_BOR_FAILED, FAULT_BOR_PROGRAMMED,
};

use crate::clocks::HSE_STARTUP_TIMEOUT_MS;

/// Reads why the MCU reset and clears the flags, so the next reset tells
/// its own cause.
pub fn take_reset_cause() -> ResetCause {
    let cause = ResetCause::from_rcc_csr(RCC.csr().read().0);
    RCC.csr().modify(|w| w.set_rmvf(true));
    cause
}

/// Core clock before `init`: the 16 MHz HSI.
const HSI_HZ: u32 = 16_000_000;

/// Starts the crystal and waits at most [`HSE_STARTUP_TIMEOUT_MS`] for it
/// (embassy-stm32 0.6.0 waits for ever, before any log line). Returns
/// whether it runs; if not, it is switched off again and the clocks come
/// from the HSI.
pub fn start_hse() -> bool {
    RCC.cr().modify(|w| w.set_hseon(true));
    for _ in 0..HSE_STARTUP_TIMEOUT_MS {
        if RCC.cr().read().hserdy() {
            return true;
        }
        cortex_m::asm::delay(HSI_HZ / 1000);
    }
    RCC.cr().modify(|w| w.set_hseon(false));
    false
}

/// Turns on the flash prefetch buffer and the ART instruction and data
/// caches. embassy-stm32 0.6.0 writes FLASH_ACR whole with only the wait
/// states, leaving all three off: 5 wait states at 168 MHz on every fetch.
/// The caches are reset first (allowed only while they are off, RM0090
/// 3.5.2).
pub fn enable_flash_accelerator() {
    FLASH.acr().modify(|w| {
        w.set_icen(false);
        w.set_dcen(false);
    });
    FLASH.acr().modify(|w| {
        w.set_icrst(true);
        w.set_dcrst(true);
    });
    FLASH.acr().modify(|w| {
        w.set_icrst(false);
        w.set_dcrst(false);
    });
    FLASH.acr().modify(|w| {
        w.set_prften(true);
        w.set_icen(true);
        w.set_dcen(true);
    });
}

/// FLASH_OPTKEYR unlock sequence (RM0090 3.7.2).
const OPT_KEYS: [u32; 2] = [0x0819_2A3B, 0x4C5D_6E7F];
/// Option byte programming takes about 16 ms at most; a generous bound in
/// polls (each one a register read, a few cycles at 168 MHz).
const OPT_BUSY_POLLS: u32 = 100_000_000;

/// Programs the brown-out reset to level 3 (2.7 V) once, if the option
/// bytes hold anything else (the factory setting is off). Returns the
/// system fault to record, if something was done. The other option bytes,
/// read protection included, are written back as read.
pub fn ensure_bor_level3() -> Option<u8> {
    let optcr = FLASH.optcr().read().0;
    if BorLevel::from_optcr(optcr) == BorLevel::Level3 {
        return None;
    }
    for key in OPT_KEYS {
        FLASH.optkeyr().write_value(key);
    }
    let idle = || (0..OPT_BUSY_POLLS).any(|_| !FLASH.sr().read().bsy());
    let mut ok = idle();
    if ok {
        FLASH
            .optcr()
            .write_value(pac::flash::regs::Optcr(optcr_with_bor_level3(optcr)));
        FLASH.optcr().modify(|w| w.set_optstrt(true));
        ok = idle();
    }
    FLASH.optcr().modify(|w| w.set_optlock(true));
    let now = BorLevel::from_optcr(FLASH.optcr().read().0);
    Some(if ok && now == BorLevel::Level3 {
        FAULT_BOR_PROGRAMMED
    } else {
        FAULT_BOR_FAILED
    })
}

/// Blinks `code` on `led` (200 ms on, 200 ms off, then a 1 s pause), so a
/// rider without a probe sees what went wrong at boot.
pub fn blink_code(led: &mut Output<'_>, code: u8) {
    for _ in 0..code {
        led.set_high();
        block_for(Duration::from_millis(200));
        led.set_low();
        block_for(Duration::from_millis(200));
    }
    block_for(Duration::from_secs(1));
}

/// A panic (after panic-probe has printed it over defmt) or a fault ends
/// here: reset, so the logger comes back and the next log records a
/// software reset. With a probe attached, probe-rs halts on the fault
/// before this runs and shows the backtrace.
#[exception]
unsafe fn HardFault(_frame: &ExceptionFrame) -> ! {
    cortex_m::peripheral::SCB::sys_reset()
}
