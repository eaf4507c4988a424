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

#[test]
fn a_silent_card_is_not_found_after_bounded_attempts() {
    let expectations = silent_acquisition(ACQUIRE_RETRIES as usize + 1);
    let mut spi = Mock::new(&expectations);
    let card = sd_card(spi.clone(), NoopDelay::new());
    assert!(matches!(card.num_bytes(), Err(Error::CardNotFound)));
    spi.done();
}
