//! The decoder's limits at their edges, with the numbers FORMAT.md states
//! written out here (not taken from the decoder's constants): the 1 s time
//! slack, the major version check, the missing frames a dropout explains.

use wobble_core::format::block::crc32;
use wobble_core::format::*;

mod format_support;
use format_support::{decode_events as decode, encode, frame};

fn jumps(file: &[u8]) -> Vec<(u64, u64)> {
    decode(file)
        .0
        .iter()
        .filter_map(|e| match e {
            Event::TimeJump { from_us, to_us } => Some((*from_us, *to_us)),
            _ => None,
        })
        .collect()
}

/// Ten frames at 100 Hz (the default rate: no log info), then one `step`
/// after the last.
fn step_after_ten(step: u64) -> Vec<u8> {
    let mut records: Vec<Record<'_>> = (0..10).map(|i| frame(i * 10_000)).collect();
    records.push(frame(90_000 + step));
    encode(&records)
}

#[test]
fn a_step_of_one_period_plus_one_second_is_no_jump_one_microsecond_more_is() {
    // FORMAT.md: forwards by more than 1 s beyond what missing frames
    // explain (none here: one period, 10 ms).
    assert_eq!(jumps(&step_after_ten(1_010_000)), []);
    assert_eq!(
        jumps(&step_after_ten(1_010_001)),
        [(90_000, 90_000 + 1_010_001)]
    );
    let (_, stats) = decode(&step_after_ten(1_010_001));
    assert_eq!((stats.forward_time_jumps, stats.time_jumps), (1, 0));
}

#[test]
fn the_slack_follows_the_stated_rate() {
    // At 50 Hz one period is 20 ms: 1.02 s is explained, 1.020001 s is not.
    let info = Record::LogInfo(LogInfo {
        t_us: 0,
        firmware: "x",
        device_id: [0; 12],
        sample_rate_hz: 50,
        run: 1,
    });
    for (step, jumped) in [(1_020_000, false), (1_020_001, true)] {
        let records = [info, frame(0), frame(20_000), frame(20_000 + step)];
        assert_eq!(!jumps(&encode(&records)).is_empty(), jumped, "{step}");
    }
}

#[test]
fn a_frame_one_microsecond_back_is_a_jump_back() {
    let records = [frame(0), frame(10_000), frame(9_999)];
    let file = encode(&records);
    assert_eq!(jumps(&file), [(10_000, 9_999)]);
    assert_eq!(decode(&file).1.time_jumps, 1);
    // The same time again is no jump.
    assert_eq!(
        jumps(&encode(&[frame(0), frame(10_000), frame(10_000)])),
        []
    );
}

#[test]
fn a_dropout_explains_one_gap_and_the_next_gap_is_a_jump_again() {
    let mut records: Vec<Record<'_>> = (0..100).map(|i| frame(i * 10_000)).collect();
    // 300 frames (3 s) dropped: 3.01 s to the next frame is explained ...
    records.push(Record::Dropout(Dropout {
        t_us: 1_000_000,
        frames_lost: 300,
        reason: DropoutReason::QueueFull,
    }));
    records.extend((0..100).map(|i| frame(4_000_000 + i * 10_000)));
    // ... but 1.5 s later with nothing dropped is not: the missing frames
    // were spent on the first gap.
    records.extend((0..10).map(|i| frame(6_490_000 + i * 10_000)));
    let file = encode(&records);
    assert_eq!(jumps(&file), [(4_990_000, 6_490_000)]);
}

#[test]
fn lost_blocks_explain_their_frames_once() {
    // 400 frames in several blocks; the second block is cut out.
    let records: Vec<Record<'_>> = (0..400).map(|i| frame(i * 10_000)).collect();
    let full = encode(&records);
    let mut file = full[..BLOCK_LEN].to_vec();
    file.extend_from_slice(&full[2 * BLOCK_LEN..]);
    let (events, stats) = decode(&file);
    assert_eq!(stats.blocks_lost, 1);
    assert!(stats.frames_lost > 0);
    assert_eq!(stats.forward_time_jumps, 0, "{events:?}");
}

/// Block 0 of a small log with its major version byte set to `major` and
/// the CRC made right again, then block 1 untouched.
fn with_major(major: u8) -> Vec<u8> {
    let records: Vec<Record<'_>> = (0..40).map(|i| frame(i * 10_000)).collect();
    let mut file = encode(&records);
    assert!(file.len() >= 2 * BLOCK_LEN);
    file[4] = major;
    let crc = crc32(&file[..508]);
    file[508..512].copy_from_slice(&crc.to_le_bytes());
    file
}

#[test]
fn another_major_version_is_skipped_as_unsupported_and_named() {
    let file = with_major(2);
    let block: &Block = file[..BLOCK_LEN].try_into().unwrap();
    assert_eq!(
        block::BlockHeader::parse(block),
        Err(BlockError::UnsupportedVersion(2))
    );
    let (events, stats) = decode(&file);
    assert!(events.contains(&Event::Skipped {
        offset: 0,
        len: BLOCK_LEN as u64,
        cause: SkipCause::UnsupportedVersion(2),
    }));
    assert_eq!(stats.blocks, 1, "only block 1 decodes");
    assert_eq!(stats.damaged_blocks, 0, "its CRC is right: not damage");
    assert_eq!(
        BlockError::UnsupportedVersion(2).to_string(),
        "unsupported format major version 2"
    );
    // Major 0 too: only 1 is read.
    let zero = with_major(0);
    let (events, _) = decode(&zero);
    assert!(matches!(
        events[0],
        Event::Skipped {
            cause: SkipCause::UnsupportedVersion(0),
            ..
        }
    ));
}

#[test]
fn a_newer_minor_version_decodes() {
    let mut file = with_major(1);
    file[5] = 9;
    let crc = crc32(&file[..508]);
    file[508..512].copy_from_slice(&crc.to_le_bytes());
    let (_, stats) = decode(&file);
    assert_eq!((stats.blocks, stats.bytes_skipped), (2, 0));
}

fn spacing_reports(rate_hz: u16, step_us: u64) -> Vec<OutOfRange> {
    let mut records = vec![Record::LogInfo(LogInfo {
        t_us: 0,
        firmware: "x",
        device_id: [0; 12],
        sample_rate_hz: rate_hz,
        run: 1,
    })];
    records.extend((0..400).map(|i| frame(i * step_us)));
    let file = encode(&records);
    decode(&file)
        .0
        .iter()
        .filter_map(|e| match e {
            Event::OutOfRange { what, .. } => Some(*what),
            _ => None,
        })
        .collect()
}

#[test]
fn a_stated_rate_the_frames_contradict_is_flagged_once() {
    // 10 ms frames under a header saying 50 Hz, and 20 ms frames under 100 Hz.
    assert_eq!(
        spacing_reports(50, 10_000),
        [OutOfRange::FrameSpacing {
            stated_hz: 50,
            spacing_us: 10_000
        }]
    );
    assert_eq!(
        spacing_reports(100, 20_000),
        [OutOfRange::FrameSpacing {
            stated_hz: 100,
            spacing_us: 20_000
        }]
    );
    // Frames that keep to the stated rate, within 5 %, are not flagged.
    assert_eq!(spacing_reports(100, 10_000), []);
    assert_eq!(spacing_reports(100, 10_400), []);
    assert_eq!(spacing_reports(200, 5_000), []);
}

#[test]
fn back_to_back_markers_cost_no_crc_each_and_hide_nothing_after_them() {
    let records: Vec<Record<'_>> = (0..100).map(|i| frame(i * 10_000)).collect();
    let log = encode(&records);
    let mut file = b"WBLK".repeat(1 << 16);
    file.extend_from_slice(&log);
    let (events, stats) = decode(&file);
    assert_eq!(stats.frames, 100);
    assert_eq!(stats.bytes_skipped, 1 << 18);
    assert_eq!(
        events
            .iter()
            .filter(|e| matches!(e, Event::Skipped { .. }))
            .count(),
        1
    );
}
