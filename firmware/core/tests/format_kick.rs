//! The kick ring-down record (tag 0x83, format 1.1): its bytes as
//! `firmware/FORMAT.md` lays them out, the round trip, a body longer than
//! this reader knows (a later minor version), and a 1.0 card still decoding.

use wobble_core::format::block::VERSION_MINOR;
use wobble_core::format::*;

mod format_support;
use format_support::{assert_round_trips, decode, encode, frame, reseal};

const KICK: KickRingDown = KickRingDown {
    t_us: 1_985_000,
    speed_mm_s: Some(3_104),
    freq_chz: 623,
    sigma_milli_per_s: -1_812,
    sigma_se_milli_per_s: 47,
    amp_cdeg: 153,
    segments: 9,
};

#[test]
fn the_record_is_laid_out_as_documented() {
    // After a frame at 2.0 s (the cursor), a kick 15 ms before it.
    let file = encode(&[frame(2_000_000), Record::Kick(KICK)]);
    let payload = &file[24..];
    // Frame: tag, three time bytes (the block's first frame is 10 ms early
    // against its cursor, t0), 21 body bytes.
    let kick = &payload[25..];
    let delta = -15_000_i64;
    let zz = ((delta << 1) ^ (delta >> 63)) as u64; // 29 999
    let mut expected = vec![0x83, 14];
    expected.extend([
        (zz & 0x7f) as u8 | 0x80,
        ((zz >> 7) & 0x7f) as u8 | 0x80,
        (zz >> 14) as u8,
    ]);
    expected.extend(3_104_u16.to_le_bytes());
    expected.extend(623_u16.to_le_bytes());
    expected.extend((-1_812_i16).to_le_bytes());
    expected.extend(47_u16.to_le_bytes());
    expected.extend(153_u16.to_le_bytes());
    expected.push(9);
    assert_eq!(&kick[..expected.len()], &expected[..]);
    let payload_len = usize::from(u16::from_le_bytes([file[6], file[7]]));
    assert_eq!(payload_len, 25 + expected.len(), "nothing after the kick");
    // The record came with 1.1; every later minor version writes it alike.
    assert_eq!(file[5], VERSION_MINOR);
}

#[test]
fn kicks_round_trip_with_and_without_speed() {
    let unknown = KickRingDown {
        speed_mm_s: None,
        sigma_milli_per_s: 250,
        ..KICK
    };
    let records = [
        frame(0),
        frame(10_000),
        Record::Kick(KICK),
        frame(20_000),
        Record::Kick(unknown),
    ];
    assert_round_trips(&records);
}

#[test]
fn a_longer_body_from_a_later_minor_version_decodes_its_known_fields() {
    let mut file = encode(&[frame(0), Record::Kick(KICK), frame(10_000)]);
    // Lengthen the kick's body by two bytes, as a 1.2 writer appending a
    // field would: the frame after it must still be found.
    reseal(&mut file, |h, block| {
        let at = 24 + 25;
        let len = usize::from(block[at + 1]);
        let end = 24 + usize::from(h.payload_len);
        let tail: Vec<u8> = block[at + 2 + len..end].to_vec();
        block[at + 1] = (len + 2) as u8;
        block[at + 2 + len..at + 4 + len].copy_from_slice(&[0xAA, 0xBB]);
        block[at + 4 + len..at + 4 + len + tail.len()].copy_from_slice(&tail);
        h.payload_len += 2;
        h.version_minor = 2;
    });
    let (decoded, stats) = decode(&file);
    assert_eq!(decoded, [frame(0), Record::Kick(KICK), frame(10_000)]);
    assert_eq!(stats.unknown_records, 0);
}

#[test]
fn a_card_of_format_1_0_still_decodes() {
    let records = [frame(0), frame(10_000), frame(20_000)];
    let mut file = encode(&records);
    reseal(&mut file, |h, _| h.version_minor = 0);
    let (decoded, stats) = decode(&file);
    assert_eq!(decoded, records);
    assert_eq!(stats.unknown_records, 0);
}
