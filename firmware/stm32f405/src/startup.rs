//! Register work before and right after `embassy_stm32::init`: the reset
//! cause, a bounded wait for the crystal, the flash accelerator, the
//! brown-out level (read at boot, programmed by the self-test), the stack
//! guard and high-water mark, and a visible failure code. The decisions (what the
//! flags mean, which option word to program, which fault to record) are the
//! core's `boot` module.

use core::mem::MaybeUninit;
use core::ptr::addr_of_mut;
use cortex_m_rt::{exception, ExceptionFrame};
use embassy_stm32::gpio::Output;
use embassy_stm32::pac::{self, FLASH, RCC};
use embassy_time::{block_for, Duration};

use wobble_core::boot::{
    crystal_failed_last_run, optcr_with_bor_level3, panic_streak, BorCheck, BorLevel, ResetCause,
    CRYSTAL_FAILED_MARK, FAULT_RESET_MARK, FLASH_SR_ERRORS,
};

use wobble_core::supply::{bor_step, BorStep, SupplyReading};

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

/// Stops the logger's timers while a debugger halts the core
/// (DBGMCU_APB1_FZ, RM0090 38.16.4: DBG_TIM3_STOP, DBG_TIM5_STOP and
/// DBG_IWDG_STOP): TIM3 is embassy-time's driver, TIM5 the wheel's and the
/// IMU's capture time base, whose counts `wheel_capture::EdgeClock` maps
/// onto embassy-time's, so the two stop and go together and a halt looks to
/// the firmware like no time at all (no burst of missed ticks, no
/// watchdog reset, no stale captures on resume). The watchdog's start calls
/// it again (`watchdog::feed`). No effect without
/// a debugger; the register is cleared only by a power-on reset.
pub fn freeze_timers_when_halted() {
    pac::DBGMCU.apb1fzr().modify(|w| {
        w.set_tim3(true);
        w.set_tim5(true);
        w.set_iwdg(true);
    });
}

/// FLASH_OPTKEYR unlock sequence (RM0090 3.7.2).
const OPT_KEYS: [u32; 2] = [0x0819_2A3B, 0x4C5D_6E7F];
/// Option byte programming takes about 16 ms at most; a generous bound in
/// polls (each one a register read, a few cycles at 168 MHz).
const OPT_BUSY_POLLS: u32 = 100_000_000;

/// The brown-out level the option bytes hold (FLASH_OPTCR is loaded from
/// them at reset). The boot only reads it: writing the option bytes
/// rewrites the whole user option sector, read protection included, and a
/// power cut during the write at an unknown supply could leave the chip
/// protected; the self-test, which a person asks for at the bench,
/// programs it ([`program_bor_level3`]).
pub fn bor_level() -> BorLevel {
    BorLevel::from_optcr(FLASH.optcr().read().0)
}

/// Programs the brown-out reset to level 3 (2.7 V) if the option bytes
/// hold anything else (the factory setting is off) and the core's
/// `supply::bor_step` allows it on `supply`, the supply just measured
/// through VREFINT (`adapters::supply::measure`): a supply too low, or not
/// measured, leaves the option bytes alone. The other option bytes, read
/// protection included, are written back as read. Stale FLASH_SR error
/// flags are cleared first and the ones the write raised are reported and
/// cleared; the stored value is verified by the next self-test, after a
/// power cycle loads it.
pub fn program_bor_level3(supply: Option<SupplyReading>) -> BorCheck {
    let optcr = FLASH.optcr().read().0;
    let was = BorLevel::from_optcr(optcr);
    if let BorStep::Keep(check) = bor_step(was, supply) {
        return check;
    }
    let clear_errors = || {
        FLASH
            .sr()
            .write_value(pac::flash::regs::Sr(FLASH_SR_ERRORS))
    };
    clear_errors();
    for key in OPT_KEYS {
        FLASH.optkeyr().write_value(key);
    }
    let idle = || (0..OPT_BUSY_POLLS).any(|_| !FLASH.sr().read().bsy());
    let mut went_idle = idle();
    if went_idle {
        FLASH
            .optcr()
            .write_value(pac::flash::regs::Optcr(optcr_with_bor_level3(optcr)));
        FLASH.optcr().modify(|w| w.set_optstrt(true));
        went_idle = idle();
    }
    let sr = FLASH.sr().read().0;
    clear_errors();
    FLASH.optcr().modify(|w| w.set_optlock(true));
    BorCheck::after_write(was, went_idle, sr)
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

extern "C" {
    /// Top of the stack (cortex-m-rt's linker script: the end of RAM).
    static _stack_start: u32;
    /// Bottom of the stack: the end of the statics (`.bss`, `.uninit`).
    static _stack_end: u32;
}

/// Bytes at the bottom of the stack no access is allowed to (an MPU
/// region's size must be a power of two, its base aligned to it).
const GUARD_BYTES: u32 = 256;
/// MPU_RASR: execute never (bit 28), AP = 0b000 (no access, bits 26:24),
/// SIZE = log2(bytes) - 1 (bits 5:1), ENABLE (bit 0).
const GUARD_RASR: u32 = (1 << 28) | ((GUARD_BYTES.trailing_zeros() - 1) << 1) | 1;
/// MPU_CTRL: the default memory map everywhere else (PRIVDEFENA), on.
const MPU_CTRL_PRIVDEFENA_ENABLE: u32 = (1 << 2) | 1;

/// The lowest stack address in use, and the top, as numbers.
fn stack_bounds() -> (u32, u32) {
    let end = &raw const _stack_end as u32;
    let start = &raw const _stack_start as u32;
    (end, start)
}

/// The guard's base: the first [`GUARD_BYTES`]-aligned address above the
/// statics.
fn guard_base() -> u32 {
    let (end, _) = stack_bounds();
    end.next_multiple_of(GUARD_BYTES)
}

/// The stack guard's region, as addresses: its base and its end (the
/// lowest address the stack may use).
pub fn guard_region() -> (u32, u32) {
    let base = guard_base();
    (base, base + GUARD_BYTES)
}

/// Puts a no-access MPU region at the bottom of the stack: a stack that
/// grows into it faults (and resets, see [`HardFault`]; if the fault's own
/// stacking faults too, the core locks up and the watchdog resets it)
/// instead of silently overwriting the statics below it (the RTT buffer,
/// then the queues). The region is below the deepest use ever measured by
/// far (board.md).
pub fn guard_stack() {
    // SAFETY: region 0 is the only MPU region this firmware sets; the rest
    // of the memory map stays the default one (PRIVDEFENA).
    unsafe {
        let mpu = &*cortex_m::peripheral::MPU::PTR;
        mpu.rnr.write(0);
        mpu.rbar.write(guard_base());
        mpu.rasr.write(GUARD_RASR);
        mpu.ctrl.write(MPU_CTRL_PRIVDEFENA_ENABLE);
    }
    cortex_m::asm::dsb();
    cortex_m::asm::isb();
}

/// The deepest the stack has been since reset, and its size above the
/// guard, bytes: cortex-m-rt paints the stack at reset (`paint-stack`), and
/// use scrubs the paint off. Scans up from the guard to the first word
/// that is not paint.
pub fn stack_use() -> (u32, u32) {
    let (_, start) = stack_bounds();
    let bottom = guard_base() + GUARD_BYTES;
    let mut p = bottom;
    while p < start {
        // SAFETY: `bottom..start` is the stack's RAM above the guard,
        // word-aligned; reading it races only with the stack's own writes
        // below the current frame, which are not paint anyway.
        let word = unsafe { core::ptr::read_volatile(p as *const u32) };
        if word != cortex_m_rt::STACK_PAINT_VALUE {
            break;
        }
        p += 4;
    }
    (start - p, start - bottom)
}

/// An interrupt without a handler of its own (enabled by mistake in a
/// driver, or by a bit flip): masked in the NVIC and logged, and the ride
/// goes on. cortex-m-rt's default handler would spin in it for ever, with
/// the watchdog's reset as the only way out.
#[exception]
unsafe fn DefaultHandler(irqn: i16) {
    if let Ok(n) = usize::try_from(irqn) {
        // SAFETY: writing ICER only disables the interrupt that fired.
        unsafe {
            let nvic = &*cortex_m::peripheral::NVIC::PTR;
            nvic.icer[n / 32].write(1 << (n % 32));
        }
    }
    defmt::error!("unexpected interrupt {}: masked", irqn);
}

/// The failure-reset streak kept across resets: a magic word, the count,
/// the fault handler's mark ([`FAULT_RESET_MARK`]) and the clock security
/// handler's ([`CRYSTAL_FAILED_MARK`]), in `.uninit` (not
/// zeroed at reset; noise after a power-on, which the magic word tells
/// apart).
#[link_section = ".uninit.PANIC_STREAK"]
static mut PANIC_STREAK: MaybeUninit<[u32; 4]> = MaybeUninit::uninit();
const STREAK_MAGIC: u32 = 0x5742_4C21;

fn keep_streak(n: u32) {
    // SAFETY: written only in thread mode (boot, then the watchdog task)
    // and by the hard fault handler on its way to a reset, never borrowed.
    unsafe { addr_of_mut!(PANIC_STREAK).write_volatile(MaybeUninit::new([STREAK_MAGIC, n, 0, 0])) }
}

/// This boot's failure-reset streak (`wobble_core::boot::panic_streak`:
/// panics, faults and watchdog resets in a row; a debug probe's reset is a
/// fresh start), kept for the next boot with the fault mark cleared; and
/// whether the last run ended in the clock security system's reset
/// (`boot::crystal_failed_last_run`, the mark cleared too).
pub fn take_panic_streak(cause: ResetCause) -> (u32, bool) {
    // SAFETY: as in `keep_streak`; any bit pattern is a valid `[u32; 4]`.
    let [magic, count, mark, crystal] =
        unsafe { addr_of_mut!(PANIC_STREAK).read_volatile().assume_init() };
    let valid = magic == STREAK_MAGIC;
    let n = panic_streak(
        valid.then_some(count),
        cause,
        valid && mark == FAULT_RESET_MARK,
    );
    keep_streak(n);
    (n, crystal_failed_last_run(valid, crystal))
}

/// The logger ran long enough: the next failure starts a new streak.
pub fn clear_panic_streak() {
    keep_streak(0);
}

/// Marks the coming software reset as the firmware's own, after a panic
/// or a fault (`boot::counts_towards_streak`); the count is left as it is.
fn mark_fault_reset() {
    // SAFETY: the hard fault handler runs with every other handler and
    // thread mode preempted and resets right after; a single word write.
    unsafe {
        let words = addr_of_mut!(PANIC_STREAK).cast::<u32>();
        words.add(2).write_volatile(FAULT_RESET_MARK);
    }
}

/// Turns on the clock security system once the clocks run from the
/// crystal (RM0090 6.2.7): if the crystal stops mid-ride, the hardware
/// switches the system clock to the HSI and raises the NMI
/// ([`NonMaskableInt`]), instead of the clocks stopping with it.
pub fn enable_clock_security() {
    RCC.cr().modify(|w| w.set_csson(true));
}

/// The crystal failed (the clock security system's NMI; nothing else
/// raises it here). The CSS flag is cleared (else the NMI repeats), the
/// failure is marked in RAM that survives the reset
/// (`boot::CRYSTAL_FAILED_MARK`) and the MCU resets: the boot then logs it
/// from thread mode and records system fault 9, finds no crystal and runs
/// the whole clock tree from the HSI, so every timer, baud rate and sample
/// time is right again instead of 16 MHz HSI under a 168 MHz set-up. No
/// defmt here: the NMI preempts everything, a defmt call in progress
/// included, and a second one inside it would corrupt the stream (its
/// critical section cannot mask the NMI).
#[exception]
unsafe fn NonMaskableInt() {
    RCC.cir().modify(|w| w.set_cssc(true));
    // SAFETY: as in `mark_fault_reset`: nothing runs after this handler but
    // the reset; a single word write.
    unsafe {
        let words = addr_of_mut!(PANIC_STREAK).cast::<u32>();
        words.add(3).write_volatile(CRYSTAL_FAILED_MARK);
    }
    cortex_m::peripheral::SCB::sys_reset()
}

/// A panic (after panic-probe has printed it over defmt) or a fault ends
/// here: the reset is marked as a failure for the next boot's streak (a
/// debug probe's reset is not), then the MCU resets, so the logger comes
/// back and the next log records a software reset. With a probe attached,
/// probe-rs halts on the fault before this runs and shows the backtrace.
#[exception]
unsafe fn HardFault(_frame: &ExceptionFrame) -> ! {
    mark_fault_reset();
    cortex_m::peripheral::SCB::sys_reset()
}
