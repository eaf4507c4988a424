//! What the codes stored on the card mean, in words for reports: one table
//! for the fault codes of every source (as `firmware/FORMAT.md` lists them,
//! keyed by the firmware's own `FAULT_*` constants) and one for the dropout
//! reasons.

use wobble_core::app::sampler::{
    FAULT_IMU_BAD_SAMPLE, FAULT_IMU_NO_RESPONSE, FAULT_IMU_SKIPPED, FAULT_STEER_OVERRUN,
    FAULT_STEER_READ,
};
use wobble_core::boot::{
    FAULT_BOR_FAILED, FAULT_BOR_LOW, FAULT_BOR_PROGRAMMED, FAULT_HSE_FAILED, FAULT_RESET_BROWN_OUT,
    FAULT_RESET_LOW_POWER, FAULT_RESET_PIN, FAULT_RESET_POWER_ON, FAULT_RESET_SOFTWARE,
    FAULT_RESET_UNKNOWN, FAULT_RESET_WATCHDOG, FAULT_RESET_WINDOW_WATCHDOG,
};
use wobble_core::config::{
    FAULT_BAD_VALUE, FAULT_OBSOLETE_KEY, FAULT_REJECTED, FAULT_SYNTAX, FAULT_UNKNOWN_KEY,
    FAULT_UNREADABLE,
};
use wobble_core::drivers::gnss_bringup::{
    FAULT_RECEIVER_LOST, FAULT_SETUP_SILENT, FAULT_SETUP_SLOW, FAULT_SETUP_UNCONFIRMED,
};
use wobble_core::format::{DropoutReason, FaultSource};
use wobble_core::gps::{
    FAULT_CHECKSUM, FAULT_FRAMING, FAULT_NO_CHECKSUM, FAULT_OUT_OF_RANGE, FAULT_OVERLONG,
    FAULT_UNPARSEABLE,
};
use wobble_core::logger::{
    FAULT_CARD_ABSENT, FAULT_CARD_FORMAT, FAULT_CARD_FULL, FAULT_CARD_WRITE,
};

/// Every fault code the firmware records: (source, code, meaning).
pub const FAULT_MEANINGS: [(FaultSource, u8, &str); 37] = [
    (
        FaultSource::Imu,
        FAULT_IMU_NO_RESPONSE,
        "the IMU did not answer",
    ),
    (
        FaultSource::Imu,
        FAULT_IMU_BAD_SAMPLE,
        "stale or impossible sample (stuck sensor)",
    ),
    (
        FaultSource::Imu,
        FAULT_IMU_SKIPPED,
        "a sample the sensor made reached no frame (a gap in its data-ready times, FIFO overflow or invalid packet)",
    ),
    (
        FaultSource::Steering,
        FAULT_STEER_READ,
        "the steering ADC could not be read",
    ),
    (
        FaultSource::Steering,
        FAULT_STEER_OVERRUN,
        "the steering ADC overran (samples lost) and was restarted",
    ),
    (FaultSource::Gps, FAULT_CHECKSUM, "NMEA checksum mismatch"),
    (
        FaultSource::Gps,
        FAULT_NO_CHECKSUM,
        "NMEA line without checksum",
    ),
    (
        FaultSource::Gps,
        FAULT_OVERLONG,
        "line longer than NMEA allows",
    ),
    (
        FaultSource::Gps,
        FAULT_FRAMING,
        "line cut short or holding a bad byte",
    ),
    (
        FaultSource::Gps,
        FAULT_UNPARSEABLE,
        "RMC/GGA/GLL/VTG/GSA/ZDA sentence the parser rejected",
    ),
    (
        FaultSource::Gps,
        FAULT_OUT_OF_RANGE,
        "sentence with a field out of range (position off the globe, minutes of 60 or more, absurd speed, altitude or satellites: the sentence is not used); an HDOP over 25.4 or negative (left unknown, the rest used), or a 23:59:60 on a day that cannot end with a leap second (the fix goes without its UTC)",
    ),
    (FaultSource::Gps, FAULT_SETUP_UNCONFIRMED, "set-up: no command set confirmed (logging at the receiver's own baud and rate)"),
    (FaultSource::Gps, FAULT_SETUP_SLOW, "set-up: configured, but fixes come slower than 15 Hz"),
    (FaultSource::Gps, FAULT_RECEIVER_LOST, "receiver lost: no valid sentence for 3 s while logging; the set-up runs again"),
    (FaultSource::Gps, FAULT_SETUP_SILENT, "set-up: no valid NMEA at any baud rate (logging at 9600)"),
    (
        FaultSource::Card,
        FAULT_CARD_ABSENT,
        "card absent or unreadable",
    ),
    (FaultSource::Card, FAULT_CARD_WRITE, "a block write failed"),
    (FaultSource::Card, FAULT_CARD_FULL, "card full"),
    (
        FaultSource::Card,
        FAULT_CARD_FORMAT,
        "card without a FAT16 or FAT32 volume (exFAT, GPT or unformatted): format it FAT32",
    ),
    (
        FaultSource::Config,
        FAULT_SYNTAX,
        "`CONFIG.TXT` line without `=` or key",
    ),
    (FaultSource::Config, FAULT_UNKNOWN_KEY, "unknown key"),
    (
        FaultSource::Config,
        FAULT_BAD_VALUE,
        "value that does not parse or is out of range",
    ),
    (
        FaultSource::Config,
        FAULT_REJECTED,
        "values that do not work together: their section fell back to defaults",
    ),
    (
        FaultSource::Config,
        FAULT_UNREADABLE,
        "unreadable bytes or a file too long",
    ),
    (
        FaultSource::Config,
        FAULT_OBSOLETE_KEY,
        "obsolete key, skipped: `detector.wheel_circumference_m` (the detector uses `wheel.circumference_m`)",
    ),
    (
        FaultSource::System,
        FAULT_RESET_POWER_ON,
        "reset cause: power-on",
    ),
    (
        FaultSource::System,
        FAULT_RESET_BROWN_OUT,
        "reset cause: brown-out (supply below the BOR threshold)",
    ),
    (
        FaultSource::System,
        FAULT_RESET_WATCHDOG,
        "reset cause: independent watchdog (a task hung)",
    ),
    (
        FaultSource::System,
        FAULT_RESET_WINDOW_WATCHDOG,
        "reset cause: window watchdog",
    ),
    (
        FaultSource::System,
        FAULT_RESET_SOFTWARE,
        "reset cause: software (the firmware reset itself after a panic or fault)",
    ),
    (
        FaultSource::System,
        FAULT_RESET_PIN,
        "reset cause: NRST pin (reset button, debug probe)",
    ),
    (
        FaultSource::System,
        FAULT_RESET_LOW_POWER,
        "reset cause: low-power management",
    ),
    (
        FaultSource::System,
        FAULT_RESET_UNKNOWN,
        "reset cause unknown (no flag set)",
    ),
    (
        FaultSource::System,
        FAULT_HSE_FAILED,
        "the crystal did not start: clocks from the internal oscillator",
    ),
    (
        FaultSource::System,
        FAULT_BOR_PROGRAMMED,
        "brown-out reset level was below 2.7 V and has been programmed to level 3 (firmware that programmed it at boot)",
    ),
    (
        FaultSource::System,
        FAULT_BOR_FAILED,
        "programming the brown-out level failed (firmware that programmed it at boot)",
    ),
    (
        FaultSource::System,
        FAULT_BOR_LOW,
        "brown-out reset level below 2.7 V: the field self-test programs it",
    ),
];

/// What fault `code` of `source` means; a log from a newer firmware may
/// hold codes this table does not know.
#[must_use]
pub fn fault_meaning(source: FaultSource, code: u8) -> &'static str {
    FAULT_MEANINGS
        .iter()
        .find(|(s, c, _)| *s == source && *c == code)
        .map_or("unknown code (newer firmware?)", |(_, _, meaning)| meaning)
}

/// What a dropout reason means.
#[must_use]
pub fn dropout_meaning(reason: DropoutReason) -> &'static str {
    match reason {
        DropoutReason::QueueFull => "queue full: the card stalled longer than designed",
        DropoutReason::CardUnavailable => "card unavailable",
        DropoutReason::SamplerOverrun => "sampler overrun",
        DropoutReason::Other(_) => "unknown reason (newer firmware?)",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// FORMAT.md and this table list the same codes with the same words.
    #[test]
    fn table_matches_the_format_document() {
        let doc = include_str!("../../firmware/FORMAT.md");
        let source_name = |s: FaultSource| match s {
            FaultSource::Imu => "IMU",
            FaultSource::Steering => "steering",
            FaultSource::Card => "card",
            FaultSource::Config => "config",
            FaultSource::Gps => "GPS",
            FaultSource::System => "system",
            _ => "?",
        };
        let rows: Vec<&str> = doc
            .lines()
            .filter(|l| l.starts_with("| ") && l.matches('|').count() == 5)
            .filter(|l| {
                l.split('|')
                    .nth(2)
                    .is_some_and(|c| c.trim().parse::<u8>().is_ok())
            })
            .collect();
        assert_eq!(rows.len(), FAULT_MEANINGS.len(), "{rows:#?}");
        for (source, code, meaning) in FAULT_MEANINGS {
            let expected = format!(
                "| {} {} | {code} | {meaning} |",
                source.code(),
                source_name(source)
            );
            assert!(
                rows.iter().any(|r| r.starts_with(&expected)),
                "FORMAT.md has no row starting {expected:?}"
            );
        }
    }

    /// Each (source, code) has one meaning: a code shared by two faults
    /// would name one of them wrongly in every report.
    #[test]
    fn each_code_means_one_thing() {
        for (i, (source, code, _)) in FAULT_MEANINGS.iter().enumerate() {
            for (other, other_code, _) in &FAULT_MEANINGS[i + 1..] {
                assert!(
                    !(source == other && code == other_code),
                    "{source:?} code {code} listed twice"
                );
            }
        }
        assert_eq!(
            fault_meaning(FaultSource::Gps, 10),
            "set-up: no valid NMEA at any baud rate (logging at 9600)"
        );
    }

    #[test]
    fn unknown_codes_say_so() {
        assert_eq!(fault_meaning(FaultSource::Gps, 1), "NMEA checksum mismatch");
        assert!(fault_meaning(FaultSource::Gps, 99).starts_with("unknown"));
        assert!(fault_meaning(FaultSource::Other(9), 1).starts_with("unknown"));
        assert!(dropout_meaning(DropoutReason::Other(7)).starts_with("unknown"));
    }
}
