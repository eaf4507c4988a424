//! The margin record (tag 0x84, format 1.2): its bytes as
//! `firmware/FORMAT.md` lays them out, the round trip with and without each
//! speed, a state of a later minor version, and cards of 1.1 and 1.0 still
//! decoding.

use wobble_core::detector::WobbleSpeed;
use wobble_core::format::block::VERSION_MINOR;
use wobble_core::format::*;

mod format_support;
use format_support::{assert_round_trips, decode, encode, frame, reseal};

const MARGIN: MarginRecord = MarginRecord {
    t_us: 2_003_000,
    state: MarginState::Approaching,
    speed_mm_s: Some(3_412),
    lower_mm_s: Some(3_905),
    estimate_mm_s: Some(4_180),
    upper_mm_s: Some(4_570),
    kicks: 11,
};

#[test]
fn the_record_is_laid_out_as_documented() {
    // After a frame at 2.0 s (the cursor), 3 ms after it.
    let file = encode(&[frame(2_000_000), Record::Margin(MARGIN)]);
    let payload = &file[24..];
    // Frame: tag, three time bytes, 21 body bytes.
    let margin = &payload[25..];
    // zigzag(3000) = 6000 = 0xF0 0x2E as LEB128.
    let mut expected = vec![0x84, 12, 0xF0, 0x2E, 1];
    for v in [3_412_u16, 3_905, 4_180, 4_570] {
        expected.extend(v.to_le_bytes());
    }
    expected.push(11);
    assert_eq!(&margin[..expected.len()], &expected[..]);
    let payload_len = usize::from(u16::from_le_bytes([file[6], file[7]]));
    assert_eq!(payload_len, 25 + expected.len(), "nothing after the record");
    assert_eq!(file[5], VERSION_MINOR);
    assert_eq!(VERSION_MINOR, 2);
}

#[test]
fn unknown_speeds_are_0xffff_and_states_have_their_codes() {
    let none = MarginRecord {
        state: MarginState::Clear,
        speed_mm_s: None,
        estimate_mm_s: None,
        upper_mm_s: None,
        ..MARGIN
    };
    let file = encode(&[frame(2_000_000), Record::Margin(none)]);
    let body = &file[24 + 25 + 4..24 + 25 + 14];
    assert_eq!(body[0], 2);
    assert_eq!(&body[1..3], &[0xFF, 0xFF]);
    assert_eq!(&body[3..5], &3_905_u16.to_le_bytes());
    assert_eq!(&body[5..9], &[0xFF; 4]);
    for (state, code) in [
        (MarginState::Estimate, 0),
        (MarginState::Approaching, 1),
        (MarginState::Clear, 2),
        (MarginState::Other(7), 7),
    ] {
        assert_eq!(state.code(), code);
        assert_eq!(MarginState::from_code(code), state);
    }
}

#[test]
fn margin_records_round_trip_among_frames_and_kicks() {
    let kick = KickRingDown {
        t_us: 1_985_000,
        speed_mm_s: Some(3_104),
        freq_chz: 623,
        sigma_milli_per_s: -1_812,
        sigma_se_milli_per_s: 47,
        amp_cdeg: 153,
        segments: 9,
    };
    let estimate = MarginRecord {
        state: MarginState::Estimate,
        estimate_mm_s: None,
        upper_mm_s: None,
        ..MARGIN
    };
    let later = MarginRecord {
        state: MarginState::Other(9),
        speed_mm_s: None,
        lower_mm_s: None,
        ..MARGIN
    };
    let records = [
        frame(1_990_000),
        frame(2_000_000),
        Record::Kick(kick),
        Record::Margin(estimate),
        Record::Margin(MARGIN),
        frame(2_010_000),
        Record::Margin(later),
    ];
    assert_round_trips(&records);
}

#[test]
fn the_record_is_built_from_the_estimate_in_force() {
    let e = WobbleSpeed {
        estimate_mps: Some(4.1804),
        lower_mps: 3.9051,
        upper_mps: None,
        kicks: 11,
    };
    let r = MarginRecord::new(5, MarginState::Estimate, Some(3.4116), Some(&e));
    assert_eq!(
        r,
        MarginRecord {
            t_us: 5,
            state: MarginState::Estimate,
            speed_mm_s: Some(3_412),
            lower_mm_s: Some(3_905),
            estimate_mm_s: Some(4_180),
            upper_mm_s: None,
            kicks: 11,
        }
    );
    // No estimate: no speeds of it; a speed past the field is never read
    // back as "unknown".
    let r = MarginRecord::new(5, MarginState::Clear, Some(1e9), None);
    assert_eq!(r.speed_mm_s, Some(0xFFFE));
    assert_eq!((r.lower_mm_s, r.kicks), (None, 0));
}

#[test]
fn cards_of_format_1_1_and_1_0_still_decode() {
    let kick = KickRingDown {
        t_us: 5_000,
        speed_mm_s: None,
        freq_chz: 700,
        sigma_milli_per_s: -500,
        sigma_se_milli_per_s: 20,
        amp_cdeg: 120,
        segments: 6,
    };
    for (minor, records) in [
        (1, vec![frame(0), Record::Kick(kick), frame(10_000)]),
        (0, vec![frame(0), frame(10_000), frame(20_000)]),
    ] {
        let mut file = encode(&records);
        reseal(&mut file, |h, _| h.version_minor = minor);
        let (decoded, stats) = decode(&file);
        assert_eq!(decoded, records, "format 1.{minor}");
        assert_eq!(stats.unknown_records, 0);
    }
}
