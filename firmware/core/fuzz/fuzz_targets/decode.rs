//! Any bytes, fed in any chunking: the decoder never panics, always makes
//! progress, and accounts for every byte as a block or as skipped.
//!
//! `cargo fuzz run decode` from `firmware/core` (needs a nightly toolchain).
#![no_main]

use libfuzzer_sys::fuzz_target;
use wobble_core::format::{Decoder, BLOCK_LEN};

fuzz_target!(|input: (u16, &[u8])| {
    let (chunk_len, data) = input;
    let chunk_len = usize::from(chunk_len).max(BLOCK_LEN);
    let mut decoder = Decoder::new();
    let mut start = 0;
    while start < data.len() {
        let end = (start + chunk_len).min(data.len());
        let consumed = decoder.feed(&data[start..end], end == data.len(), &mut |_| {});
        // A chunk of at least a block, or the last one, always moves on.
        assert!(consumed > 0, "no progress");
        start += consumed;
    }
    let stats = decoder.stats();
    let unwritten = stats.unwritten_blocks as usize * BLOCK_LEN;
    assert_eq!(
        stats.blocks as usize * BLOCK_LEN + stats.bytes_skipped as usize + unwritten,
        data.len()
    );
});
