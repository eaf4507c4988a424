//! Logs built and read back through the card format's own encoder and
//! decoder, for the format tests.
#![allow(dead_code)] // Each test file uses the helpers it needs.

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
