//! What the board learns at boot and writes into the next log as system
//! fault records (source 7): why the MCU reset, whether the crystal
//! started, whether the brown-out reset is below 2.7 V; and what the
//! self-test did about the brown-out level.
//!
//! The decoding works on the raw register words of the STM32F4 (RM0090:
//! RCC_CSR, FLASH_OPTCR), so the board only reads and writes registers.

use crate::format::{Fault, FaultSource};

/// System fault 1: power-on (or power-down) reset.
pub const FAULT_RESET_POWER_ON: u8 = 1;
/// System fault 2: brown-out reset: the supply fell below the BOR threshold.
pub const FAULT_RESET_BROWN_OUT: u8 = 2;
/// System fault 3: the independent watchdog reset the MCU (a task hung).
pub const FAULT_RESET_WATCHDOG: u8 = 3;
/// System fault 4: the window watchdog reset the MCU.
pub const FAULT_RESET_WINDOW_WATCHDOG: u8 = 4;
/// System fault 5: software reset: the firmware reset itself after a panic
/// or a hard fault.
pub const FAULT_RESET_SOFTWARE: u8 = 5;
/// System fault 6: reset from the NRST pin (reset button or debug probe).
pub const FAULT_RESET_PIN: u8 = 6;
/// System fault 7: low-power management reset.
pub const FAULT_RESET_LOW_POWER: u8 = 7;
/// System fault 8: no reset flag set (flags cleared by a debugger).
pub const FAULT_RESET_UNKNOWN: u8 = 8;
/// System fault 9: the crystal (HSE) did not start in time; the clocks run
/// from the internal RC oscillator (HSI, ±1 % at 25 °C).
pub const FAULT_HSE_FAILED: u8 = 9;
/// System fault 10: the brown-out reset level was below 2.7 V (factory:
/// off) and has been programmed to level 3. Recorded by firmware that
/// programmed it at boot; the self-test does it now ([`BorCheck`]).
pub const FAULT_BOR_PROGRAMMED: u8 = 10;
/// System fault 11: programming the brown-out level failed (firmware that
/// programmed it at boot).
pub const FAULT_BOR_FAILED: u8 = 11;
/// System fault 12: the brown-out reset level is below 2.7 V; the field
/// self-test programs it (the boot never writes the option bytes).
pub const FAULT_BOR_LOW: u8 = 12;

/// Why the MCU started, from the reset flags in RCC_CSR.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ResetCause {
    /// Power-on or power-down reset.
    PowerOn,
    /// Brown-out reset (supply dip without a full power-down).
    BrownOut,
    /// Independent watchdog.
    Watchdog,
    /// Window watchdog.
    WindowWatchdog,
    /// `SYSRESETREQ`: the firmware reset itself.
    Software,
    /// The NRST pin.
    Pin,
    /// Low-power management.
    LowPower,
    /// No flag set.
    Unknown,
}

/// RCC_CSR reset flags (RM0090 7.3.21).
mod csr {
    pub const LPWRRSTF: u32 = 1 << 31;
    pub const WWDGRSTF: u32 = 1 << 30;
    pub const IWDGRSTF: u32 = 1 << 29;
    pub const SFTRSTF: u32 = 1 << 28;
    pub const PORRSTF: u32 = 1 << 27;
    pub const PINRSTF: u32 = 1 << 26;
    pub const BORRSTF: u32 = 1 << 25;
}

impl ResetCause {
    /// Decodes RCC_CSR. Every reset drives NRST low, so PINRSTF comes with
    /// each cause, and a power-on sets BORRSTF as well: the specific flags
    /// are tested first, the pin last.
    #[must_use]
    pub fn from_rcc_csr(csr: u32) -> Self {
        const BY_PRIORITY: [(u32, ResetCause); 7] = [
            (csr::IWDGRSTF, ResetCause::Watchdog),
            (csr::WWDGRSTF, ResetCause::WindowWatchdog),
            (csr::LPWRRSTF, ResetCause::LowPower),
            (csr::SFTRSTF, ResetCause::Software),
            (csr::PORRSTF, ResetCause::PowerOn),
            (csr::BORRSTF, ResetCause::BrownOut),
            (csr::PINRSTF, ResetCause::Pin),
        ];
        BY_PRIORITY
            .iter()
            .find(|(flag, _)| csr & flag != 0)
            .map_or(Self::Unknown, |&(_, cause)| cause)
    }

    /// The system fault code recorded for it.
    #[must_use]
    pub const fn fault_code(self) -> u8 {
        match self {
            Self::PowerOn => FAULT_RESET_POWER_ON,
            Self::BrownOut => FAULT_RESET_BROWN_OUT,
            Self::Watchdog => FAULT_RESET_WATCHDOG,
            Self::WindowWatchdog => FAULT_RESET_WINDOW_WATCHDOG,
            Self::Software => FAULT_RESET_SOFTWARE,
            Self::Pin => FAULT_RESET_PIN,
            Self::LowPower => FAULT_RESET_LOW_POWER,
            Self::Unknown => FAULT_RESET_UNKNOWN,
        }
    }

    /// Whether a rider should hear of it: anything but a normal power-on or
    /// a deliberate reset from the pin.
    #[must_use]
    pub const fn is_abnormal(self) -> bool {
        !matches!(self, Self::PowerOn | Self::Pin)
    }

    /// Whether to blink it at boot. A software reset with a debugger
    /// attached is the probe's own reset after flashing (probe-rs resets
    /// through SYSRESETREQ), so it is recorded but not blinked; a panic
    /// under a probe is printed over defmt anyway. The debug enable bit
    /// stays set until a power-on, so in the field nothing changes.
    #[must_use]
    pub const fn blink_at_boot(self, debugger_attached: bool) -> bool {
        self.is_abnormal() && !(debugger_attached && matches!(self, Self::Software))
    }
}

/// A system fault record with `code` at `t_us`, counted once.
#[must_use]
pub const fn system_fault(code: u8, t_us: u64) -> Fault {
    Fault {
        t_us,
        source: FaultSource::System,
        code,
        count: 1,
    }
}

/// Brown-out reset threshold (FLASH_OPTCR BOR_LEV, RM0090 3.7.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BorLevel {
    /// Level 3: 2.70-3.60 V. What the logger needs: the card and the MCU
    /// stop before a sagging supply corrupts a FAT write.
    Level3,
    /// Level 2: 2.40-2.70 V.
    Level2,
    /// Level 1: 2.10-2.40 V.
    Level1,
    /// Off (factory setting): reset only at 1.8 V (POR/PDR).
    Off,
}

/// BOR_LEV field of FLASH_OPTCR: bits 3:2.
const BOR_LEV_SHIFT: u32 = 2;
const BOR_LEV_MASK: u32 = 0b11 << BOR_LEV_SHIFT;
/// OPTLOCK (bit 0) and OPTSTRT (bit 1): control bits, not option bytes.
const OPTCR_CONTROL_MASK: u32 = 0b11;

impl BorLevel {
    /// The level programmed in FLASH_OPTCR.
    #[must_use]
    pub const fn from_optcr(optcr: u32) -> Self {
        match (optcr & BOR_LEV_MASK) >> BOR_LEV_SHIFT {
            0b00 => Self::Level3,
            0b01 => Self::Level2,
            0b10 => Self::Level1,
            _ => Self::Off,
        }
    }
}

/// The FLASH_OPTCR word to program for BOR level 3: every other option
/// byte (read protection, write protection, watchdog and reset options) as
/// read, the control bits clear (the board sets OPTSTRT itself).
#[must_use]
pub const fn optcr_with_bor_level3(optcr: u32) -> u32 {
    optcr & !BOR_LEV_MASK & !OPTCR_CONTROL_MASK
}

/// Boots in a row that ended in a failure reset (a panic or a fault, or
/// the watchdog: [`counts_towards_streak`]) after which the logger stops
/// opening a new log file per boot.
pub const PANIC_LOOP_BOOTS: u32 = 3;
/// A boot that has run this long ends the streak, µs.
pub const PANIC_STREAK_CLEAR_US: u64 = 60_000_000;
/// The word the firmware's fault handler leaves in RAM that survives a
/// reset (beside the streak) just before it resets the MCU: the next boot
/// knows the software reset was its own, after a panic or a fault, and not
/// a debug probe's (probe-rs resets through the same SYSRESETREQ).
pub const FAULT_RESET_MARK: u32 = 0x4641_4C54;

/// The word the clock security system's NMI handler leaves beside the
/// streak (in RAM that survives a reset) just before it resets the MCU. The
/// handler itself logs nothing (a defmt call there could interrupt one in
/// progress and corrupt the stream): the next boot, in thread mode, finds
/// the mark ([`crystal_failed_last_run`]), logs the failure and records it.
pub const CRYSTAL_FAILED_MARK: u32 = 0x4353_5346;

/// Whether the last run ended in the clock security system's reset: the
/// kept RAM is valid (its magic word held, not a power-on's noise) and
/// holds [`CRYSTAL_FAILED_MARK`].
#[must_use]
pub const fn crystal_failed_last_run(kept_valid: bool, mark: u32) -> bool {
    kept_valid && mark == CRYSTAL_FAILED_MARK
}

/// The crystal's system fault for this boot's log: [`FAULT_HSE_FAILED`]
/// when it did not start now, and also when it failed during the last run
/// but starts again (an intermittent crystal: its failure is recorded once
/// instead of lost with the reset).
#[must_use]
pub const fn crystal_fault(started: bool, failed_last_run: bool) -> Option<u8> {
    if !started || failed_last_run {
        Some(FAULT_HSE_FAILED)
    } else {
        None
    }
}

/// Whether a reset continues the streak of failed boots: a software reset
/// the firmware's fault handler marked (`fault_marked`: a panic or a hard
/// fault), and a watchdog reset (a hang; a hang at every boot would
/// otherwise open a file per boot). A software reset without the mark (a
/// debug probe flashing or resetting the board), a power-on, the reset pin
/// and a brown-out are fresh starts.
#[must_use]
pub const fn counts_towards_streak(cause: ResetCause, fault_marked: bool) -> bool {
    match cause {
        ResetCause::Software => fault_marked,
        ResetCause::Watchdog | ResetCause::WindowWatchdog => true,
        _ => false,
    }
}

/// This boot's count of failure resets in a row, from the count kept
/// across the reset (`None` when the kept word is not valid: after a
/// power-on RAM holds noise), the reset cause and whether the fault handler
/// marked it ([`counts_towards_streak`]).
#[must_use]
pub const fn panic_streak(kept: Option<u32>, cause: ResetCause, fault_marked: bool) -> u32 {
    if !counts_towards_streak(cause, fault_marked) {
        return 0;
    }
    match kept {
        Some(n) => n.saturating_add(1),
        None => 1,
    }
}

/// Whether a boot with `streak` is in a failure loop: it writes nothing (a
/// panic or a hang at every boot would otherwise leave a new, nearly empty
/// log file per boot) and shows the last reset's code until a power cycle.
#[must_use]
pub const fn in_panic_loop(streak: u32) -> bool {
    streak >= PANIC_LOOP_BOOTS
}

/// The system fault to record at boot for the stored brown-out level.
#[must_use]
pub fn bor_fault(level: BorLevel) -> Option<u8> {
    (level != BorLevel::Level3).then_some(FAULT_BOR_LOW)
}

/// FLASH_SR error flags (RM0090 3.9.4): OPERR (bit 1), WRPERR, PGAERR,
/// PGPERR, PGSERR (bits 4-7). Each is cleared by writing 1.
pub const FLASH_SR_ERRORS: u32 = (1 << 1) | (0b1111 << 4);

/// What the self-test found or did about the brown-out level. OPTCR is
/// loaded from the stored option bytes at reset, so a level read after a
/// power cycle is what the option bytes hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BorCheck {
    /// Level 3 is stored.
    Level3,
    /// It was `was`; level 3 has been written, and is verified by the next
    /// self-test after a power cycle.
    Programmed {
        /// The level before.
        was: BorLevel,
    },
    /// The write did not complete: FLASH_SR's error flags at the end (0:
    /// the flash stayed busy past the time-out).
    Failed {
        /// The level before.
        was: BorLevel,
        /// FLASH_SR & [`FLASH_SR_ERRORS`].
        flash_sr: u32,
    },
    /// Not written: the supply, measured through VREFINT just before, is
    /// too low for level 3 (`supply::MIN_VDD_FOR_BOR3_MV`), or could not be
    /// measured. The level stays as it was.
    SupplyTooLow {
        /// The level, unchanged.
        was: BorLevel,
        /// The supply the decision went by, mV (`None`: not measured).
        vdd_mv: Option<u32>,
    },
}

impl BorCheck {
    /// How a write of level 3 over `was` ended: whether the flash went idle
    /// in time, and FLASH_SR read then.
    #[must_use]
    pub const fn after_write(was: BorLevel, went_idle: bool, flash_sr: u32) -> Self {
        let errors = flash_sr & FLASH_SR_ERRORS;
        if went_idle && errors == 0 {
            Self::Programmed { was }
        } else {
            Self::Failed {
                was,
                flash_sr: errors,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The streak after each boot of `boots` (cause, marked by the fault
    /// handler), starting from noise.
    /// The clock security system's mark is read only from RAM that kept
    /// its magic word, and only the mark itself counts; a crystal that
    /// failed during the last run is recorded even when it starts again.
    #[test]
    fn a_crystal_failure_is_recorded_by_the_next_boot() {
        assert!(crystal_failed_last_run(true, CRYSTAL_FAILED_MARK));
        assert!(!crystal_failed_last_run(false, CRYSTAL_FAILED_MARK));
        assert!(!crystal_failed_last_run(true, FAULT_RESET_MARK));
        assert!(!crystal_failed_last_run(true, 0));
        assert_eq!(crystal_fault(true, false), None);
        assert_eq!(crystal_fault(false, false), Some(FAULT_HSE_FAILED));
        assert_eq!(crystal_fault(true, true), Some(FAULT_HSE_FAILED));
        assert_eq!(crystal_fault(false, true), Some(FAULT_HSE_FAILED));
    }

    fn streaks(boots: &[(ResetCause, bool)]) -> Vec<u32> {
        let mut kept = None;
        boots
            .iter()
            .map(|&(cause, marked)| {
                let n = panic_streak(kept, cause, marked);
                kept = Some(n);
                n
            })
            .collect()
    }

    #[test]
    fn a_panic_at_every_boot_is_a_loop_after_three_and_a_fresh_start_ends_it() {
        let panics = streaks(&[(ResetCause::Software, true); 5]);
        assert_eq!(panics, [1, 2, 3, 4, 5]);
        let loops: Vec<bool> = panics.iter().map(|&n| in_panic_loop(n)).collect();
        assert_eq!(loops, [false, false, true, true, true]);
        // A power-on, the reset button, a brown-out: a fresh start.
        for cause in [ResetCause::PowerOn, ResetCause::Pin, ResetCause::BrownOut] {
            assert_eq!(panic_streak(Some(7), cause, false), 0);
            // A mark is only ever believed on a software reset.
            assert_eq!(panic_streak(Some(7), cause, true), 0);
        }
        // Noise after a power-on is never taken for a count.
        assert_eq!(panic_streak(None, ResetCause::Software, true), 1);
        assert_eq!(
            panic_streak(Some(u32::MAX), ResetCause::Software, true),
            u32::MAX
        );
    }

    /// Flashing the board three times in a minute (probe-rs resets through
    /// SYSRESETREQ, a software reset the fault handler did not mark) is no
    /// panic loop, and it ends a streak of panics as a power-on does.
    #[test]
    fn probe_resets_are_fresh_starts_not_panics() {
        let probe = (ResetCause::Software, false);
        assert_eq!(streaks(&[probe, probe, probe, probe]), [0, 0, 0, 0]);
        let panic = (ResetCause::Software, true);
        assert_eq!(streaks(&[panic, panic, probe, panic]), [1, 2, 0, 1]);
        assert!(!counts_towards_streak(ResetCause::Software, false));
    }

    /// A hang at every boot (the watchdog resets the MCU each time) is a
    /// loop like a panic at every boot, and the two add up.
    #[test]
    fn watchdog_reset_loops_count_like_panics() {
        let dog = (ResetCause::Watchdog, false);
        let panic = (ResetCause::Software, true);
        let n = streaks(&[dog, dog, dog]);
        assert_eq!(n, [1, 2, 3]);
        assert!(in_panic_loop(n[2]));
        assert_eq!(streaks(&[panic, dog, panic]), [1, 2, 3]);
        assert_eq!(panic_streak(Some(1), ResetCause::WindowWatchdog, false), 2);
        assert_eq!(
            streaks(&[dog, dog, (ResetCause::PowerOn, false), dog]),
            [1, 2, 0, 1]
        );
    }

    #[test]
    fn the_boot_only_reports_a_low_brown_out_level() {
        assert_eq!(bor_fault(BorLevel::Level3), None);
        for low in [BorLevel::Level2, BorLevel::Level1, BorLevel::Off] {
            assert_eq!(bor_fault(low), Some(FAULT_BOR_LOW));
        }
    }

    #[test]
    fn a_bor_write_is_judged_by_the_flash_error_flags() {
        let was = BorLevel::Off;
        assert_eq!(
            BorCheck::after_write(was, true, 0),
            BorCheck::Programmed { was }
        );
        // EOP (bit 0) and BSY (bit 16) are not errors.
        assert_eq!(
            BorCheck::after_write(was, true, 1 | 1 << 16),
            BorCheck::Programmed { was }
        );
        // WRPERR: the option bytes are write-protected.
        assert_eq!(
            BorCheck::after_write(was, true, 1 << 4),
            BorCheck::Failed {
                was,
                flash_sr: 1 << 4
            }
        );
        assert_eq!(
            BorCheck::after_write(was, false, 0),
            BorCheck::Failed { was, flash_sr: 0 }
        );
        // RM0090 3.9.4: OPERR, WRPERR, PGAERR, PGPERR, PGSERR.
        assert_eq!(FLASH_SR_ERRORS, 0b1111_0010);
    }

    /// RCC_CSR as read after each kind of reset (RM0090 7.3.21 and 5.3:
    /// every reset pulls NRST, a POR also sets BORRSTF).
    const AFTER_POWER_ON: u32 = csr::PORRSTF | csr::PINRSTF | csr::BORRSTF;
    const AFTER_WATCHDOG: u32 = csr::IWDGRSTF | csr::PINRSTF;
    const AFTER_SOFTWARE: u32 = csr::SFTRSTF | csr::PINRSTF;
    const AFTER_BROWN_OUT: u32 = csr::BORRSTF | csr::PINRSTF;

    #[test]
    fn each_reset_decodes_to_its_cause() {
        let cases = [
            (AFTER_POWER_ON, ResetCause::PowerOn),
            (AFTER_WATCHDOG, ResetCause::Watchdog),
            (AFTER_SOFTWARE, ResetCause::Software),
            (AFTER_BROWN_OUT, ResetCause::BrownOut),
            (csr::WWDGRSTF | csr::PINRSTF, ResetCause::WindowWatchdog),
            (csr::LPWRRSTF | csr::PINRSTF, ResetCause::LowPower),
            (csr::PINRSTF, ResetCause::Pin),
            (0, ResetCause::Unknown),
        ];
        for (csr, cause) in cases {
            // LSION/LSIRDY (bits 0, 1) and RMVF never change the cause.
            assert_eq!(ResetCause::from_rcc_csr(csr | 0b11), cause);
        }
    }

    #[test]
    fn a_watchdog_reset_after_power_on_flags_still_reads_as_watchdog() {
        // Flags accumulate until cleared: the most telling one wins.
        let csr = AFTER_POWER_ON | AFTER_WATCHDOG;
        assert_eq!(ResetCause::from_rcc_csr(csr), ResetCause::Watchdog);
    }

    #[test]
    fn every_cause_has_its_own_system_fault_code() {
        let causes = [
            ResetCause::PowerOn,
            ResetCause::BrownOut,
            ResetCause::Watchdog,
            ResetCause::WindowWatchdog,
            ResetCause::Software,
            ResetCause::Pin,
            ResetCause::LowPower,
            ResetCause::Unknown,
        ];
        let codes: Vec<u8> = causes.iter().map(|c| c.fault_code()).collect();
        assert_eq!(codes, (1..=8).collect::<Vec<u8>>());
        let fault = system_fault(ResetCause::Watchdog.fault_code(), 42);
        assert_eq!(
            fault,
            Fault {
                t_us: 42,
                source: FaultSource::System,
                code: 3,
                count: 1
            }
        );
        let abnormal: Vec<bool> = causes.iter().map(|c| c.is_abnormal()).collect();
        assert_eq!(abnormal, [false, true, true, true, true, false, true, true]);
        let blinked =
            |debugger| -> Vec<bool> { causes.iter().map(|c| c.blink_at_boot(debugger)).collect() };
        assert_eq!(blinked(false), abnormal);
        let software = causes.iter().position(|&c| c == ResetCause::Software);
        let expected: Vec<bool> = (0..causes.len())
            .map(|i| abnormal[i] && Some(i) != software)
            .collect();
        assert_eq!(blinked(true), expected);
        assert!(software.is_some_and(|i| abnormal[i]));
    }

    #[test]
    fn bor_level_reads_and_programs_only_its_field() {
        // Factory option bytes: RDP 0xAA, no write protection, BOR off,
        // software watchdog, no reset on stop/standby; OPTLOCK set.
        let factory = 0x0FFF_AAED;
        assert_eq!(BorLevel::from_optcr(factory), BorLevel::Off);
        let programmed = optcr_with_bor_level3(factory);
        assert_eq!(programmed, 0x0FFF_AAE0);
        assert_eq!(BorLevel::from_optcr(programmed), BorLevel::Level3);
        // Read protection and write protection bits are kept exactly.
        assert_eq!(programmed & 0xFFFF_FFF0, factory & 0xFFFF_FFF0);
        assert_eq!(BorLevel::from_optcr(0b0100), BorLevel::Level2);
        assert_eq!(BorLevel::from_optcr(0b1000), BorLevel::Level1);
    }
}
