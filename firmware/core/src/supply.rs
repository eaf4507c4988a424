//! The supply voltage measured through the internal reference (VREFINT),
//! and whether it is safe to enable the brown-out reset at level 3.
//!
//! The ADC converts against VDDA (on the 64-pin STM32F405, VREF+ is bonded
//! to VDDA, which must be at VDD's potential: DS8626, "General operating
//! conditions"). VREFINT is a bandgap of a known voltage on ADC1 channel 17;
//! its count rises as VDDA falls:
//!
//! ```text
//! VDDA = 3300 mV × VREFINT_CAL / VREFINT_DATA
//! ```
//!
//! where VREFINT_CAL is ST's own conversion of this chip's VREFINT at VDDA =
//! 3.3 V, stored in system memory at [`VREFINT_CAL_ADDR`]. A chip whose
//! word there is no plausible calibration falls back on the datasheet's
//! typical VREFINT (1.21 V), and decides with the lowest VDDA the reading
//! allows (VREFINT at its 1.18 V minimum).
//!
//! Level 3 is programmed only when the supply is measured above the level's
//! highest rising threshold with a margin ([`MIN_VDD_FOR_BOR3_MV`]): a
//! brown-out reset armed above the running supply would hold the chip in
//! reset at every power-on, and the option bytes could then only be changed
//! with a probe. The board reads the registers; what they mean is here.

use core::fmt::{self, Write};

use crate::boot::{BorCheck, BorLevel};
use crate::selftest::Verdict;

/// Where the factory's VREFINT conversion is stored: a 16-bit word, raw
/// 12-bit ADC data of VREFINT at 30 °C (± 5 °C) with VDDA = 3.3 V
/// (± 10 mV) (DS8626, "Internal reference voltage calibration values",
/// VREFIN_CAL, 0x1FFF 7A2A-0x1FFF 7A2B).
pub const VREFINT_CAL_ADDR: usize = 0x1FFF_7A2A;
/// The VDDA of the factory's conversion, mV.
pub const CAL_VDDA_MV: u32 = 3300;
/// The ADC's full scale at 12 bits.
pub const FULL_SCALE: u32 = 4095;
/// VREFINT, mV: minimum, typical and maximum over −40 to 105 °C (DS8626,
/// "Internal reference voltage", V_REFINT 1.18 / 1.21 / 1.24 V).
pub const VREFINT_MIN_MV: u32 = 1180;
/// Typical VREFINT, mV (see [`VREFINT_MIN_MV`]).
pub const VREFINT_TYP_MV: u32 = 1210;
/// Maximum VREFINT, mV (see [`VREFINT_MIN_MV`]).
pub const VREFINT_MAX_MV: u32 = 1240;
/// The shortest sampling time for VREFINT, µs (DS8626, T_S_vrefint: 10 µs;
/// its start-up time after TSVREFE is set, t_START, is 10 µs at most too).
pub const VREFINT_SAMPLE_US: u32 = 10;
/// Conversions averaged per measurement.
pub const SAMPLES: usize = 16;
/// Largest spread of those conversions, counts: more is a supply moving
/// while it is measured (1 count is about 2 mV of VDD at 3 V), which is
/// no measurement to program the option bytes on.
pub const MAX_SPREAD_COUNTS: u16 = 24;

/// The brown-out reset's level 3 thresholds, mV, maximum over temperature
/// (DS8626, "Embedded reset and power control block characteristics",
/// V_BOR3: falling edge 2.75 / 2.83 / 2.88 V, rising edge 2.85 / 2.92 /
/// 2.97 V min / typ / max; RM0090 3.7.1 and 5.2.2 name the level 2.70-3.60 V
/// with a hysteresis of about 100 mV). A chip released from reset needs the
/// rising one.
pub const BOR3_RISING_MAX_MV: u32 = 2970;
/// Level 3's falling threshold at its highest (see [`BOR3_RISING_MAX_MV`]).
pub const BOR3_FALLING_MAX_MV: u32 = 2880;
/// Margin over [`BOR3_RISING_MAX_MV`]: the measurement's own error (the
/// calibration's ± 10 mV at 3.3 V and ± 5 °C, VREFINT's 50 ppm/°C over a
/// ride's temperatures, a few counts of ADC error: about 30 mV) and ripple
/// on the supply, with room to spare.
pub const BOR3_MARGIN_MV: u32 = 100;
/// The lowest measured supply at which level 3 is programmed, mV.
pub const MIN_VDD_FOR_BOR3_MV: u32 = BOR3_RISING_MAX_MV + BOR3_MARGIN_MV;

/// A factory word outside this range (VREFINT 1.18-1.24 V at 3.3 V, with
/// 3 % to spare: counts 1420-1580) is no calibration: an erased 0xFFFF, a
/// 0, or another part's layout.
const PLAUSIBLE_CAL: core::ops::RangeInclusive<u16> = 1420..=1580;

/// What the conversion was scaled by.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Reference {
    /// This chip's factory value, VREFINT_CAL.
    Factory(u16),
    /// No plausible factory value (the word read is kept): the typical
    /// VREFINT, deciding with its minimum.
    Typical(u16),
}

/// The supply as measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SupplyReading {
    /// VDDA, mV.
    pub vdd_mv: u32,
    /// The lowest VDDA the reading allows, mV: `vdd_mv` with a factory
    /// value, VREFINT at its minimum without one. Decisions use this.
    pub assured_mv: u32,
    /// The mean VREFINT conversion, counts (rounded).
    pub vrefint: u16,
    /// What it was scaled by.
    pub reference: Reference,
}

/// `num_mv × count of samples / sum of samples`, rounded, mV.
fn scale(num_mv: u64, n: u64, sum: u64) -> u32 {
    u32::try_from((num_mv * n + sum / 2) / sum).unwrap_or(u32::MAX)
}

/// VDDA from `samples` (VREFINT conversions, 12-bit right-aligned) and the
/// factory word `cal` read at [`VREFINT_CAL_ADDR`]. `None` when there are
/// no samples, any is 0 or full scale (no reference connected, a shorted
/// input) or they spread over more than [`MAX_SPREAD_COUNTS`].
#[must_use]
pub fn measure(samples: &[u16], cal: u16) -> Option<SupplyReading> {
    let lo = *samples.iter().min()?;
    let hi = *samples.iter().max()?;
    if lo == 0 || u32::from(hi) >= FULL_SCALE || hi - lo > MAX_SPREAD_COUNTS {
        return None;
    }
    let n = samples.len() as u64;
    let sum: u64 = samples.iter().map(|&s| u64::from(s)).sum();
    let vrefint = u16::try_from((sum + n / 2) / n).unwrap_or(u16::MAX);
    let full = u64::from(FULL_SCALE);
    let (vdd_mv, assured_mv, reference) = if PLAUSIBLE_CAL.contains(&cal) {
        let vdd = scale(u64::from(CAL_VDDA_MV) * u64::from(cal), n, sum);
        (vdd, vdd, Reference::Factory(cal))
    } else {
        (
            scale(u64::from(VREFINT_TYP_MV) * full, n, sum),
            scale(u64::from(VREFINT_MIN_MV) * full, n, sum),
            Reference::Typical(cal),
        )
    };
    Some(SupplyReading {
        vdd_mv,
        assured_mv,
        vrefint,
        reference,
    })
}

/// What the self-test does about the brown-out level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BorStep {
    /// Write level 3 into the option bytes.
    Program,
    /// Leave the option bytes alone; the result is this.
    Keep(BorCheck),
}

/// Whether to program level 3 over the stored level `was`, given the
/// supply measured just before (`None`: no measurement). Only a supply
/// measured at [`MIN_VDD_FOR_BOR3_MV`] or more is programmed; level 3
/// already stored needs no write whatever the supply.
#[must_use]
pub fn bor_step(was: BorLevel, supply: Option<SupplyReading>) -> BorStep {
    if was == BorLevel::Level3 {
        return BorStep::Keep(BorCheck::Level3);
    }
    match supply {
        Some(s) if s.assured_mv >= MIN_VDD_FOR_BOR3_MV => BorStep::Program,
        _ => BorStep::Keep(BorCheck::SupplyTooLow {
            was,
            vdd_mv: supply.map(|s| s.assured_mv),
        }),
    }
}

/// The report's `vdd` line, after the `queue` line: the supply measured
/// through VREFINT. A check of its own, apart from `selftest::Measurements`
/// (whose ten checks readers know): it fails when the supply is not
/// measured or is below [`MIN_VDD_FOR_BOR3_MV`] (a board that browns out
/// near level 3's threshold, whether or not level 3 is stored), LED code
/// [`SUPPLY_LED_CODE`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SupplyCheck {
    /// The measurement, if there was one.
    pub reading: Option<SupplyReading>,
}

/// LED code of a failed `vdd` line: after the queue's.
pub const SUPPLY_LED_CODE: u8 = crate::selftest::QUEUE_LED_CODE + 1;

impl SupplyCheck {
    /// Pass when the supply is measured high enough for level 3.
    #[must_use]
    pub fn verdict(&self) -> Verdict {
        match self.reading {
            Some(s) if s.assured_mv >= MIN_VDD_FOR_BOR3_MV => Verdict::Pass,
            _ => Verdict::Fail,
        }
    }

    /// Writes the report line (with its newline), e.g.
    /// `vdd PASS vdd_mv=3301 vrefint=1499 cal=1500`.
    ///
    /// # Errors
    /// `out`'s error (a full buffer).
    pub fn write_line(&self, out: &mut impl Write) -> fmt::Result {
        let verdict = match self.verdict() {
            Verdict::Pass => "PASS",
            Verdict::Fail => "FAIL",
        };
        let Some(s) = self.reading else {
            return writeln!(out, "vdd {verdict} not measured (VREFINT)");
        };
        write!(
            out,
            "vdd {verdict} vdd_mv={} vrefint={}",
            s.vdd_mv, s.vrefint
        )?;
        match s.reference {
            Reference::Factory(cal) => write!(out, " cal={cal}")?,
            Reference::Typical(word) => write!(
                out,
                " no factory value (0x{word:04x}): typical VREFINT, at least {} mV",
                s.assured_mv
            )?,
        }
        if self.verdict() == Verdict::Fail {
            write!(
                out,
                ": too low to enable BOR level 3 (needs {MIN_VDD_FOR_BOR3_MV} mV)"
            )?;
        }
        writeln!(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The conversions a supply of `vdd_mv` gives a chip whose VREFINT
    /// converted to `cal` at 3.3 V.
    fn samples_at(vdd_mv: u32, cal: u16) -> [u16; SAMPLES] {
        let raw = (CAL_VDDA_MV * u32::from(cal) + vdd_mv / 2) / vdd_mv;
        [raw as u16; SAMPLES]
    }

    #[test]
    fn the_supply_is_the_calibration_scaled_by_the_reading() {
        let s = measure(&samples_at(3300, 1500), 1500).unwrap();
        assert_eq!(s.vdd_mv, 3300);
        assert_eq!(s.assured_mv, 3300);
        assert_eq!(s.vrefint, 1500);
        assert_eq!(s.reference, Reference::Factory(1500));
        // The reference reads higher as the supply falls.
        let low = measure(&samples_at(2900, 1500), 1500).unwrap();
        assert!(low.vrefint > s.vrefint);
        assert!(low.vdd_mv.abs_diff(2900) <= 2, "{low:?}");
        // The mean of the conversions, not the first.
        let mut mixed = [1500u16; SAMPLES];
        mixed[..SAMPLES / 2].fill(1510);
        let m = measure(&mixed, 1500).unwrap();
        assert_eq!(m.vrefint, 1505);
        assert_eq!(m.vdd_mv, 3289);
    }

    /// Today's self-test programmed level 3 whatever the supply: a supply
    /// measured under level 3's rising threshold plus the margin keeps the
    /// level and says why; one above it programs.
    #[test]
    fn a_low_supply_never_leads_to_programming_level_3() {
        for vdd in [2500, 2880, 2970, 3000, 3069] {
            let s = measure(&samples_at(vdd, 1500), 1500);
            let step = bor_step(BorLevel::Off, s);
            assert!(
                matches!(
                    step,
                    BorStep::Keep(BorCheck::SupplyTooLow { was: BorLevel::Off, vdd_mv: Some(mv) })
                        if mv.abs_diff(vdd) <= 2
                ),
                "{vdd} mV: {step:?}"
            );
            assert_eq!(SupplyCheck { reading: s }.verdict(), Verdict::Fail);
        }
        for vdd in [3075, 3300, 3600] {
            let s = measure(&samples_at(vdd, 1500), 1500);
            assert_eq!(bor_step(BorLevel::Level2, s), BorStep::Program, "{vdd} mV");
            assert_eq!(SupplyCheck { reading: s }.verdict(), Verdict::Pass);
        }
        // Exactly at the bound, by the reading's own arithmetic.
        let at = SupplyReading {
            vdd_mv: MIN_VDD_FOR_BOR3_MV,
            assured_mv: MIN_VDD_FOR_BOR3_MV,
            vrefint: 1612,
            reference: Reference::Factory(1500),
        };
        assert_eq!(bor_step(BorLevel::Off, Some(at)), BorStep::Program);
        let below = SupplyReading {
            assured_mv: MIN_VDD_FOR_BOR3_MV - 1,
            ..at
        };
        assert!(matches!(
            bor_step(BorLevel::Off, Some(below)),
            BorStep::Keep(_)
        ));
    }

    /// The published figures behind the bound: above level 3's highest
    /// rising threshold, which is above its highest falling one.
    #[test]
    fn the_bound_is_above_every_level_3_threshold() {
        const {
            assert!(BOR3_FALLING_MAX_MV < BOR3_RISING_MAX_MV);
            assert!(MIN_VDD_FOR_BOR3_MV == 3070);
            // A 3.3 V regulator 5 % low still passes.
            assert!(MIN_VDD_FOR_BOR3_MV < 3300 * 95 / 100);
        }
    }

    #[test]
    fn no_measurement_keeps_the_level_and_level_3_needs_no_write() {
        assert_eq!(
            bor_step(BorLevel::Off, None),
            BorStep::Keep(BorCheck::SupplyTooLow {
                was: BorLevel::Off,
                vdd_mv: None
            })
        );
        // Stored already: nothing to write, whatever the supply.
        let low = measure(&samples_at(2800, 1500), 1500);
        assert_eq!(
            bor_step(BorLevel::Level3, low),
            BorStep::Keep(BorCheck::Level3)
        );
        assert_eq!(
            bor_step(BorLevel::Level3, None),
            BorStep::Keep(BorCheck::Level3)
        );
    }

    /// Samples that are no measurement: none, a 0 or full scale, or a
    /// supply moving while it was measured.
    #[test]
    fn unsteady_or_broken_conversions_are_no_measurement() {
        assert_eq!(measure(&[], 1500), None);
        let mut s = samples_at(3300, 1500);
        s[3] = 0;
        assert_eq!(measure(&s, 1500), None);
        s[3] = 4095;
        assert_eq!(measure(&s, 1500), None);
        let mut moving = samples_at(3300, 1500);
        moving[0] += MAX_SPREAD_COUNTS + 1;
        assert_eq!(measure(&moving, 1500), None);
        moving[0] -= 1;
        assert!(measure(&moving, 1500).is_some());
    }

    /// An erased or missing factory word: the typical VREFINT gives the
    /// figure, its minimum the decision, so a supply that would pass with
    /// the typical value can still be kept from programming.
    #[test]
    fn without_a_factory_value_the_lowest_possible_supply_decides() {
        for word in [0xFFFF, 0x0000, 1000, 2000] {
            // 1.21 V at 3.2 V: 1548 counts.
            let s = measure(&[1548; SAMPLES], word).unwrap();
            assert_eq!(s.reference, Reference::Typical(word));
            assert!(s.vdd_mv.abs_diff(3200) <= 2, "{s:?}");
            // 1.18 V would mean 3.12 V.
            assert!(s.assured_mv.abs_diff(3121) <= 2, "{s:?}");
            assert_eq!(bor_step(BorLevel::Off, Some(s)), BorStep::Program);
            // 1.21 V at 3.1 V: typical says 3100, the minimum 3023: kept.
            let s = measure(&[1598; SAMPLES], word).unwrap();
            assert!(s.vdd_mv >= MIN_VDD_FOR_BOR3_MV, "{s:?}");
            assert!(matches!(
                bor_step(BorLevel::Off, Some(s)),
                BorStep::Keep(BorCheck::SupplyTooLow { .. })
            ));
        }
    }

    #[test]
    fn the_report_line_gives_the_supply_and_why_it_failed() {
        let line = |reading| {
            let mut text = String::new();
            SupplyCheck { reading }.write_line(&mut text).unwrap();
            text
        };
        assert_eq!(
            line(measure(&samples_at(3300, 1500), 1500)),
            "vdd PASS vdd_mv=3300 vrefint=1500 cal=1500\n"
        );
        assert_eq!(
            line(measure(&[1678; SAMPLES], 1500)),
            "vdd FAIL vdd_mv=2950 vrefint=1678 cal=1500: too low to enable BOR level 3 \
             (needs 3070 mV)\n"
        );
        assert_eq!(
            line(measure(&[1548; SAMPLES], 0xFFFF)),
            "vdd PASS vdd_mv=3201 vrefint=1548 no factory value (0xffff): typical VREFINT, \
             at least 3122 mV\n"
        );
        assert_eq!(line(None), "vdd FAIL not measured (VREFINT)\n");
        // It reads back as a report line.
        let mut report = String::from(crate::selftest::HEADER);
        report.push('\n');
        report.push_str(&line(measure(&[1678; SAMPLES], 1500)));
        let mut seen = Vec::new();
        crate::selftest::read_report(&report, &mut |l| seen.push((l.check, l.verdict))).unwrap();
        assert_eq!(seen, [("vdd", Verdict::Fail)]);
    }
}
