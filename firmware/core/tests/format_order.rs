//! Blocks out of order, copied, flushed and rewritten: every unique valid
//! block is decoded once, whatever its number says.

use wobble_core::format::block::BlockHeader;
use wobble_core::format::*;

fn frame(t_us: u64) -> Record<'static> {
    Record::Frame(Frame {
        t_us,
        steer_cdeg: (t_us / 10_000) as i16,
        ..Frame::default()
    })
}

fn info() -> Record<'static> {
    Record::LogInfo(LogInfo {
        t_us: 0,
        firmware: "order",
        device_id: [1; 12],
        sample_rate_hz: 100,
        run: 5,
    })
}

/// The sealed blocks of `records`.
fn blocks(records: &[Record<'_>]) -> Vec<Block> {
    let mut enc = BlockEncoder::new();
    let mut out = Vec::new();
    for r in records {
        out.extend(enc.push(r).unwrap().copied());
    }
    out.extend(enc.finish().copied());
    out
}

fn ride(frames: u64) -> Vec<Block> {
    let mut records = vec![info()];
    records.extend((0..frames).map(|i| frame(i * 10_000)));
    blocks(&records)
}

fn decode(file: &[u8]) -> (Vec<u64>, usize, DecodeStats) {
    let mut dec = Decoder::new();
    let mut times = Vec::new();
    let mut infos = 0;
    dec.feed(file, true, &mut |e| match e {
        Event::Record(Record::Frame(f)) => times.push(f.t_us),
        Event::Record(Record::LogInfo(_)) => infos += 1,
        _ => {}
    });
    (times, infos, *dec.stats())
}

fn sorted(mut v: Vec<u64>) -> Vec<u64> {
    v.sort_unstable();
    v
}

#[test]
fn swapped_neighbours_lose_nothing() {
    let b = ride(300);
    let n = b.len();
    assert!(n >= 6);
    let mut file = Vec::new();
    for pair in b.chunks(2) {
        for block in pair.iter().rev() {
            file.extend_from_slice(block);
        }
    }
    let (times, infos, stats) = decode(&file);
    assert_eq!(infos, 1);
    assert_eq!(
        sorted(times),
        (0..300).map(|i| i * 10_000).collect::<Vec<_>>()
    );
    assert_eq!(stats.blocks, n as u64);
    assert_eq!((stats.repeated_blocks, stats.frames), (0, 300));
}

#[test]
fn a_stray_block_numbered_zero_in_front_hides_no_header() {
    let log = ride(100);
    // A block 0 of another ride (other times, other header).
    let mut other = vec![Record::LogInfo(LogInfo {
        t_us: 0,
        firmware: "stray",
        device_id: [2; 12],
        sample_rate_hz: 100,
        run: 9,
    })];
    other.extend((0..5).map(|i| frame(7_000_000 + i * 10_000)));
    let stray = blocks(&other)[0];
    let mut file = stray.to_vec();
    file.extend(log.concat());
    let (times, infos, stats) = decode(&file);
    assert_eq!(infos, 2, "both headers decoded");
    assert_eq!(times.len(), 105);
    assert_eq!(stats.repeated_blocks, 0);
}

#[test]
fn a_block_numbered_ahead_hides_nothing_after_it() {
    let b = ride(600);
    let mut file = b[0].to_vec();
    // Block 0 re-sealed with the number 5 put right after block 0.
    let mut ahead = b[1];
    let mut h = BlockHeader::parse(&ahead).unwrap();
    h.seq = 5;
    h.seal(&mut ahead);
    file.extend_from_slice(&ahead);
    for block in &b[1..] {
        file.extend_from_slice(block);
    }
    let (times, _, stats) = decode(&file);
    assert_eq!(stats.blocks, b.len() as u64 + 1);
    assert_eq!(stats.repeated_blocks, 0);
    let frames_of_b1 = decode(&b[1]).0.len();
    assert_eq!(times.len(), 600 + frames_of_b1);
}

/// A log whose last block was flushed with `first` frames and then
/// rewritten in place with `more` frames besides, both versions kept:
/// the flushed block and the fuller one.
fn flushed_and_fuller(first: u64, more: u64) -> (Vec<Block>, Block, Block) {
    let mut enc = BlockEncoder::new();
    let mut closed = Vec::new();
    let mut records = vec![info()];
    records.extend((0..first).map(|i| frame(i * 10_000)));
    for r in &records {
        closed.extend(enc.push(r).unwrap().copied());
    }
    let flushed = *enc.snapshot().unwrap();
    for i in first..first + more {
        assert!(enc.push(&frame(i * 10_000)).unwrap().is_none());
    }
    let fuller = *enc.finish().unwrap();
    (closed, flushed, fuller)
}

#[test]
fn a_flush_and_its_fuller_rewrite_are_one_block_in_either_order() {
    let (closed, flushed, fuller) = flushed_and_fuller(40, 5);
    let all: Vec<u64> = (0..45).map(|i| i * 10_000).collect();
    for versions in [[flushed, fuller], [fuller, flushed]] {
        let mut file = closed.concat();
        for v in versions {
            file.extend_from_slice(&v);
        }
        let (times, _, stats) = decode(&file);
        assert_eq!(times, all, "each frame once, in time order");
        assert_eq!(stats.blocks, closed.len() as u64 + 1, "counted once");
        assert_eq!(stats.frames, 45);
        assert_eq!(stats.blocks_lost + stats.frames_lost, 0);
    }
    // Flushed first: its fuller version adds the new frames only.
    let mut file = closed.concat();
    file.extend_from_slice(&flushed);
    file.extend_from_slice(&fuller);
    assert_eq!(decode(&file).2.rewritten_blocks, 1);
}

#[test]
fn two_different_blocks_with_one_number_are_both_data() {
    let b = ride(100);
    let last = b.len() - 1;
    // Another block numbered like the last one, with frames of its own.
    let mut enc = BlockEncoder::new();
    let mut other = None;
    for i in 0..3 {
        enc.push(&frame(5_000_000 + i * 10_000)).unwrap();
    }
    if let Some(block) = enc.finish() {
        let mut block = *block;
        let mut h = BlockHeader::parse(&block).unwrap();
        h.seq = last as u32;
        h.seal(&mut block);
        other = Some(block);
    }
    let mut file = b.concat();
    file.extend_from_slice(&other.unwrap());
    let (times, _, stats) = decode(&file);
    assert_eq!(times.len(), 103);
    assert_eq!(stats.blocks, b.len() as u64 + 1);
    assert_eq!(stats.repeated_blocks, 0);
}

#[test]
fn a_copy_is_skipped_and_counted_once_whatever_its_place() {
    let b = ride(300);
    // Block 2 copied in front of the log, and again at the end.
    let mut file = b[2].to_vec();
    file.extend(b.concat());
    file.extend_from_slice(&b[2]);
    let (times, _, stats) = decode(&file);
    assert_eq!(
        sorted(times),
        (0..300).map(|i| i * 10_000).collect::<Vec<_>>()
    );
    assert_eq!(stats.blocks, b.len() as u64);
    assert_eq!(stats.repeated_blocks, 2);
    assert_eq!(stats.bytes_skipped, 2 * BLOCK_LEN as u64);
}

/// Whether a decoder that walked `file` (by `feed`, or by `scan` in
/// chunks) says its valid blocks were in sequence order.
fn walked_in_order(file: &[u8]) -> (bool, bool) {
    let mut fed = Decoder::new();
    fed.feed(file, true, &mut |_| {});
    // A scan in chunks, what it leaves of one passed again with the next.
    let mut scanned = Decoder::new();
    let mut rest = file;
    while !rest.is_empty() {
        let take = rest.len().min(3 * BLOCK_LEN + 100);
        let used = scanned.scan(
            &rest[..take],
            take == rest.len(),
            &mut |_| {},
            &mut |_, _| {},
        );
        assert!(used > 0, "three blocks make progress");
        rest = &rest[used..];
    }
    (fed.in_sequence_order(), scanned.in_sequence_order())
}

#[test]
fn the_decoder_says_whether_the_blocks_it_walked_were_in_order() {
    let blocks = ride(400);
    assert!(blocks.len() >= 4);
    let file = |order: &[usize]| -> Vec<u8> {
        order
            .iter()
            .flat_map(|&i| blocks[i].iter().copied())
            .collect()
    };
    let n = blocks.len();
    let in_order: Vec<usize> = (0..n).collect();
    // A gap (a block lost) and garbage between blocks leave the order.
    let with_gap: Vec<usize> = (0..n).filter(|&i| i != 2).collect();
    let mut damaged = file(&in_order);
    damaged.splice(BLOCK_LEN..BLOCK_LEN, [0x5a; 300]);
    assert_eq!(walked_in_order(&file(&in_order)), (true, true));
    assert_eq!(walked_in_order(&file(&with_gap)), (true, true));
    assert_eq!(walked_in_order(&damaged), (true, true));
    // Two neighbours swapped, a copy, the last block first: not in order.
    let mut swapped = in_order.clone();
    swapped.swap(1, 2);
    let copied: Vec<usize> = (0..n).chain([n - 1]).collect();
    let last_first: Vec<usize> = std::iter::once(n - 1).chain(0..n - 1).collect();
    for order in [swapped, copied, last_first] {
        assert_eq!(walked_in_order(&file(&order)), (false, false), "{order:?}");
    }
}
