//! A card that never answers (none inserted) is given up after
//! `ACQUIRE_RETRIES + 1` attempts of CMD0, each polled to embedded-sdmmc's
//! command timeout and followed by its 255-byte flush, and reported as
//! not found; nothing else is sent.

mod sd_support;

use embedded_hal_mock::eh1::delay::NoopDelay;
use embedded_hal_mock::eh1::spi::Mock;
use embedded_sdmmc::SdCardError as Error;
use sd_support::*;
use wobble_core::drivers::sdcard::{sd_card, ACQUIRE_RETRIES};

/// Response polls of one command before embedded-sdmmc times out: its
/// 10 000 retries (about 100 ms at 10 µs each) plus the first poll.
const POLLS_PER_COMMAND: usize = 10_001;
/// Bytes of 0xFF embedded-sdmmc clocks out after a CMD0 timeout.
const FLUSH_BYTES: usize = 255;

#[test]
fn a_silent_card_is_not_found_after_bounded_attempts() {
    let silent = || byte(0xFF, NOTHING);
    let attempt = || -> Spi {
        let polls = std::iter::repeat_with(silent).take(POLLS_PER_COMMAND + FLUSH_BYTES);
        std::iter::once(send(0, 0)).chain(polls).flatten().collect()
    };
    let attempts = ACQUIRE_RETRIES as usize + 1;
    let expectations: Spi = std::iter::repeat_with(attempt)
        .take(attempts)
        .chain([silent()])
        .flatten()
        .collect();
    let mut spi = Mock::new(&expectations);
    let card = sd_card(spi.clone(), NoopDelay::new());
    assert!(matches!(card.num_bytes(), Err(Error::CardNotFound)));
    spi.done();
}
