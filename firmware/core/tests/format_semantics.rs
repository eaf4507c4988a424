//! Blocks that pass their CRC but hold what the firmware cannot write: the
//! decoder reports and drops the impossible, and never lets it hide the rest.

use wobble_core::format::block::BlockHeader;
use wobble_core::format::*;

mod format_support;
use format_support::{decode_events as decode, encode, frame};

fn frames(events: &[Event<'_>]) -> Vec<u64> {
    events
        .iter()
        .filter_map(|e| match e {
            Event::Record(Record::Frame(f)) => Some(f.t_us),
            _ => None,
        })
        .collect()
}

fn jumps(events: &[Event<'_>]) -> Vec<(u64, u64)> {
    events
        .iter()
        .filter_map(|e| match e {
            Event::TimeJump { from_us, to_us } => Some((*from_us, *to_us)),
            _ => None,
        })
        .collect()
}

const THREE_DAYS_US: u64 = 3 * 86_400 * 1_000_000;

#[test]
fn a_forward_jump_is_reported_but_a_dropout_explains_its_gap() {
    let mut records: Vec<Record<'_>> = (0..100).map(|i| frame(i * 10_000)).collect();
    records.extend((0..100).map(|i| frame(THREE_DAYS_US + i * 10_000)));
    // 300 frames dropped by the logger (3 s), then frames resume 3 s later.
    records.push(Record::Dropout(Dropout {
        t_us: THREE_DAYS_US + 990_000,
        frames_lost: 300,
        reason: DropoutReason::QueueFull,
    }));
    records.extend((0..100).map(|i| frame(THREE_DAYS_US + 4_000_000 + i * 10_000)));
    let file = encode(&records);
    let (events, stats) = decode(&file);
    assert_eq!(jumps(&events), [(990_000, THREE_DAYS_US)]);
    assert_eq!(stats.forward_time_jumps, 1);
    assert_eq!(stats.time_jumps, 0);
    assert_eq!(frames(&events).len(), 300);
}

#[test]
fn a_block_of_far_future_times_in_front_is_a_jump_back_not_a_span() {
    let far = 1u64 << 62;
    let mut records: Vec<Record<'_>> = (0..30).map(|i| frame(far + i * 10_000)).collect();
    records.extend((0..200).map(|i| frame(i * 10_000)));
    let (events, stats) = decode_owned(encode(&records));
    assert_eq!(stats.time_jumps, 1);
    assert_eq!(events, [(far + 290_000, 0)]);
}

fn decode_owned(file: Vec<u8>) -> (Vec<(u64, u64)>, DecodeStats) {
    let (events, stats) = decode(&file);
    (jumps(&events), stats)
}

/// Rewrites block `i` of `file` with `edit` applied to its header, resealed.
fn reseal(file: &mut [u8], i: usize, edit: impl FnOnce(&mut BlockHeader)) {
    let block: &mut Block = (&mut file[i * BLOCK_LEN..(i + 1) * BLOCK_LEN])
        .try_into()
        .unwrap();
    let mut header = BlockHeader::parse(block).unwrap();
    edit(&mut header);
    header.seal(block);
}

#[test]
fn a_crafted_block_numbered_last_in_front_hides_nothing() {
    let records: Vec<Record<'_>> = (0..400).map(|i| frame(i * 10_000)).collect();
    let clean = encode(&records);
    let blocks = clean.len() / BLOCK_LEN;
    let mut file = clean[..BLOCK_LEN].to_vec();
    file.extend_from_slice(&clean);
    reseal(&mut file, 0, |h| h.seq = u32::MAX);
    let (events, stats) = decode(&file);
    // The front block's frames, then every frame of the log, shifted out of
    // its place by the block in front.
    let front = frames(&decode(&clean[..BLOCK_LEN]).0).len();
    let t = frames(&events);
    assert_eq!(t.len(), front + 400);
    let all: Vec<u64> = (0..400).map(|i| i * 10_000).collect();
    assert_eq!(&t[front..], &all[..]);
    assert_eq!(stats.repeated_blocks, 0);
    assert_eq!(stats.blocks, blocks as u64 + 1);
}

#[test]
fn one_block_repeated_through_the_file_is_decoded_once() {
    let records: Vec<Record<'_>> = (0..10).map(|i| frame(i * 10_000)).collect();
    let one = encode(&records);
    assert_eq!(one.len(), BLOCK_LEN);
    let file = one.repeat(4096);
    let (events, stats) = decode(&file);
    assert_eq!(frames(&events).len(), 10);
    assert_eq!(stats.repeated_blocks, 4095);
    assert_eq!(stats.bytes_skipped, 4095 * BLOCK_LEN as u64);
    // One report of the repeated stretch, not one per block.
    let skips = events
        .iter()
        .filter(|e| {
            matches!(
                e,
                Event::Skipped {
                    cause: SkipCause::Repeated,
                    ..
                }
            )
        })
        .count();
    assert_eq!(skips, 1);
}

#[test]
fn impossible_header_and_gps_values_are_reported_and_replaced_or_dropped() {
    let info = LogInfo {
        t_us: 0,
        firmware: "x",
        device_id: [0; 12],
        sample_rate_hz: 0,
        run: 1,
    };
    let bad_fix = GpsFix {
        t_us: 10,
        lat_e7: Some(2_147_000_000),
        lon_e7: Some(68_800_000),
        utc: Some(UtcTime {
            days_since_2000: 65_535,
            ms_of_day: 4_293_000_000,
        }),
        fix: FixMode::Fix3d,
        ..GpsFix::default()
    };
    let leap = GpsFix {
        t_us: 20,
        utc: Some(UtcTime {
            days_since_2000: 6_209,
            ms_of_day: 86_400_500,
        }),
        ..GpsFix::default()
    };
    let sync = UtcSync {
        t_us: 30,
        unix_ms: u64::MAX,
    };
    let file = encode(&[
        Record::LogInfo(info),
        Record::Gps(bad_fix),
        Record::Gps(leap),
        Record::UtcSync(sync),
        frame(40),
    ]);
    let (events, stats) = decode(&file);
    let out_of_range: Vec<OutOfRange> = events
        .iter()
        .filter_map(|e| match e {
            Event::OutOfRange { what, .. } => Some(*what),
            _ => None,
        })
        .collect();
    assert_eq!(
        out_of_range,
        [
            OutOfRange::SampleRate(0),
            OutOfRange::GpsFields(2),
            OutOfRange::UtcSync
        ]
    );
    assert_eq!(stats.out_of_range, 3);
    let records: Vec<Record<'_>> = events
        .iter()
        .filter_map(|e| match e {
            Event::Record(r) => Some(*r),
            _ => None,
        })
        .collect();
    let Record::LogInfo(i) = records[0] else {
        panic!("{records:?}")
    };
    assert_eq!(i.sample_rate_hz, limits::DEFAULT_SAMPLE_RATE_HZ);
    let Record::Gps(f) = records[1] else {
        panic!("{records:?}")
    };
    assert_eq!((f.lat_e7, f.utc, f.fix), (None, None, FixMode::None));
    assert_eq!(records[2], Record::Gps(leap), "a leap second is kept");
    assert!(
        matches!(records[3], Record::Frame(_)),
        "the sync is dropped"
    );
}
