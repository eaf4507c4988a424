//! Blocks of zeros at block offsets are unwritten space (`FORMAT.md`,
//! "Unwritten space"): counted as such, not as skipped bytes, and never
//! hiding a lost block or a damaged one.

use wobble_core::format::*;

mod format_support;
use format_support::{decode, decode_events, encode, frame};

const ZEROS: [u8; BLOCK_LEN] = [0; BLOCK_LEN];

/// A log of 400 frames (several blocks).
fn log() -> Vec<u8> {
    let records: Vec<Record<'_>> = (0..400).map(|i| frame(i * 10_000)).collect();
    encode(&records)
}

fn skips(events: &[Event<'_>]) -> Vec<(u64, u64, SkipCause)> {
    events
        .iter()
        .filter_map(|e| match e {
            Event::Skipped { offset, len, cause } => Some((*offset, *len, *cause)),
            _ => None,
        })
        .collect()
}

/// Asserts that `file` fed in chunks of several sizes gives `stats`, as
/// whole.
fn same_in_chunks(file: &[u8], stats: DecodeStats) {
    for chunk in [100, 512, 513, 700, 777, 1000, 1536, 4096] {
        assert_eq!(stats_in_chunks(file, chunk), stats, "chunks of {chunk}");
    }
}

/// The stats of `file` fed in chunks of `chunk` bytes.
fn stats_in_chunks(file: &[u8], chunk: usize) -> DecodeStats {
    let mut dec = Decoder::new();
    let mut pending: Vec<u8> = Vec::new();
    for piece in file.chunks(chunk) {
        pending.extend_from_slice(piece);
        let used = dec.feed(&pending, false, &mut |_| {});
        pending.drain(..used);
    }
    dec.feed(&pending, true, &mut |_| {});
    *dec.stats()
}

#[test]
fn zeros_after_the_data_are_no_loss() {
    let log = log();
    let mut file = log.clone();
    for _ in 0..7 {
        file.extend_from_slice(&ZEROS);
    }
    let (records, stats) = decode(&file);
    assert_eq!(records, decode(&log).0);
    assert_eq!(stats.unwritten_blocks, 7);
    assert_eq!((stats.bytes_skipped, stats.blocks_lost), (0, 0));
    // However the stream is cut into chunks.
    same_in_chunks(&file, stats);
}

#[test]
fn a_damaged_block_before_the_zeros_is_skipped_alone() {
    let mut file = log();
    let blocks = file.len() / BLOCK_LEN;
    file[(blocks - 1) * BLOCK_LEN + 100] ^= 0x40;
    for _ in 0..5 {
        file.extend_from_slice(&ZEROS);
    }
    let (events, stats) = decode_events(&file);
    let at = ((blocks - 1) * BLOCK_LEN) as u64;
    assert_eq!(skips(&events), [(at, BLOCK_LEN as u64, SkipCause::Damaged)]);
    assert_eq!((stats.damaged_blocks, stats.unwritten_blocks), (1, 5));
}

#[test]
fn a_block_of_zeros_inside_the_log_is_still_a_gap() {
    let mut file = log();
    assert!(file.len() >= 4 * BLOCK_LEN);
    file[2 * BLOCK_LEN..3 * BLOCK_LEN].copy_from_slice(&ZEROS);
    let (_, stats) = decode_events(&file);
    assert_eq!(stats.unwritten_blocks, 1);
    assert_eq!(stats.blocks_lost, 1);
    assert!(stats.frames_lost > 0, "{stats:?}");
}

#[test]
fn zeros_off_the_block_offsets_are_garbage() {
    // 100 bytes of junk, 512 zeros, then the log: no block of zeros starts
    // at a block offset, so all 612 bytes are skipped.
    let mut file = vec![0x55; 100];
    file.extend_from_slice(&ZEROS);
    let log = log();
    file.extend_from_slice(&log);
    let (events, stats) = decode_events(&file);
    assert_eq!(skips(&events), [(0, 612, SkipCause::Garbage)]);
    assert_eq!(stats.unwritten_blocks, 0);
    assert_eq!(decode(&file).0, decode(&log).0);
}

#[test]
fn a_block_with_one_byte_set_is_not_unwritten() {
    let mut block = ZEROS;
    block[511] = 1;
    let mut file = log();
    let end = file.len() as u64;
    file.extend_from_slice(&block);
    file.extend_from_slice(&ZEROS);
    let (events, stats) = decode_events(&file);
    assert_eq!(
        skips(&events),
        [(end, BLOCK_LEN as u64, SkipCause::Garbage)]
    );
    assert_eq!(stats.unwritten_blocks, 1);
}

#[test]
fn zeros_after_garbage_start_at_the_next_block_offset_in_any_chunks() {
    // The log, 100 bytes of garbage, then 4 blocks' worth of zeros: the
    // garbage stretch runs to the next block offset, 3 whole blocks of
    // zeros follow at block offsets, and 100 bytes of zeros end the file.
    let mut file = log();
    let end = file.len() as u64;
    file.extend_from_slice(&[0x55; 100]);
    for _ in 0..4 {
        file.extend_from_slice(&ZEROS);
    }
    let (events, stats) = decode_events(&file);
    assert_eq!(
        skips(&events),
        [
            (end, BLOCK_LEN as u64, SkipCause::Garbage),
            (end + 4 * BLOCK_LEN as u64, 100, SkipCause::TruncatedTail)
        ]
    );
    assert_eq!(stats.unwritten_blocks, 3);
    same_in_chunks(&file, stats);
}

#[test]
fn a_damaged_block_before_the_zeros_is_skipped_alone_in_any_chunks() {
    let mut file = log();
    let blocks = file.len() / BLOCK_LEN;
    file[(blocks - 2) * BLOCK_LEN + 100] ^= 0x40;
    file.truncate((blocks - 1) * BLOCK_LEN);
    for _ in 0..5 {
        file.extend_from_slice(&ZEROS);
    }
    let (_, stats) = decode_events(&file);
    assert_eq!((stats.damaged_blocks, stats.unwritten_blocks), (1, 5));
    assert_eq!(stats.bytes_skipped, BLOCK_LEN as u64);
    same_in_chunks(&file, stats);
}
