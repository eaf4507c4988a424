//! Logs built and read back through the card format's own encoder and
//! decoder, for the format tests.
#![allow(dead_code)] // Each test file uses the helpers it needs.

use wobble_core::format::block::{BlockHeader, BLOCK_LEN};
use wobble_core::format::*;

/// A frame at `t_us` with every sensor field zero.
pub fn frame(t_us: u64) -> Record<'static> {
    Record::Frame(Frame {
        t_us,
        ..Frame::default()
    })
}

/// The blocks of `records`, sealed (the last one too, if it holds any).
pub fn encode(records: &[Record<'_>]) -> Vec<u8> {
    let mut enc = BlockEncoder::new();
    let mut file = Vec::new();
    for r in records {
        if let Some(b) = enc.push(r).unwrap() {
            file.extend_from_slice(b);
        }
    }
    if let Some(b) = enc.finish() {
        file.extend_from_slice(b);
    }
    file
}

/// Every event the decoder reports for `file`, and its statistics.
pub fn decode_events(file: &[u8]) -> (Vec<Event<'_>>, DecodeStats) {
    let mut dec = Decoder::new();
    let mut events = Vec::new();
    dec.feed(file, true, &mut |e| events.push(e));
    (events, *dec.stats())
}

/// The frames, kicks and margin records the decoder reports for `file`
/// (the records that own no borrowed text), and its statistics.
pub fn decode(file: &[u8]) -> (Vec<Record<'static>>, DecodeStats) {
    let mut dec = Decoder::new();
    let mut out = Vec::new();
    dec.feed(file, true, &mut |e| {
        if let Event::Record(r) = e {
            match r {
                Record::Frame(f) => out.push(Record::Frame(f)),
                Record::Kick(k) => out.push(Record::Kick(k)),
                Record::Margin(m) => out.push(Record::Margin(m)),
                _ => {}
            }
        }
    });
    (out, *dec.stats())
}

/// Asserts that `records` come back from their encoded log exactly, with
/// no record left unknown.
pub fn assert_round_trips(records: &[Record<'static>]) {
    let (decoded, stats) = decode(&encode(records));
    assert_eq!(decoded, records);
    assert_eq!(stats.unknown_records, 0);
}

/// Rewrites block 0 of `file`: `edit` gets its header and bytes (CRC
/// checked first), then the block is resealed.
pub fn reseal(file: &mut [u8], edit: impl FnOnce(&mut BlockHeader, &mut [u8])) {
    let block: &mut Block = (&mut file[..BLOCK_LEN]).try_into().unwrap();
    let mut header = BlockHeader::parse(block).unwrap();
    edit(&mut header, block);
    header.seal(block);
}
