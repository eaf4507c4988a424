//! The card block device identifies a card at the slow clock, runs it at
//! the data clock, and after any error identifies it again before the next
//! access: a card that was missing, then inserted, then pulled.

mod sd_support;

use std::cell::RefCell;

use embedded_hal_mock::eh1::delay::NoopDelay;
use embedded_hal_mock::eh1::spi::Mock;
use embedded_sdmmc::{Block, BlockCount, BlockDevice, BlockIdx, SdCardError};
use sd_support::*;
use wobble_core::drivers::sdcard::{Card, ACQUIRE_RETRIES, IDENTIFICATION_CLOCK_HZ};

const DATA_CLOCK_HZ: u32 = 21_000_000;

/// A CSD version 2.0 with C_SIZE 15159: (15159 + 1) × 1024 blocks; the
/// last byte is its CRC7 and end bit.
fn csd() -> [u8; 16] {
    let mut csd = [
        0x40, 0x0E, 0x00, 0x32, 0x5B, 0x59, 0x00, 0x00, 0x3B, 0x37, 0x7F, 0x80, 0x0A, 0x40, 0x00, 0,
    ];
    csd[15] = (crc7(&csd[..15]) << 1) | 1;
    csd
}
const BLOCKS: u32 = 15_160 * 1024;

thread_local! {
    static CLOCKS: RefCell<Vec<u32>> = const { RefCell::new(Vec::new()) };
}

fn set_clock(_: &mut Mock<u8>, hz: u32) {
    CLOCKS.with(|c| c.borrow_mut().push(hz));
}

fn take_clocks() -> Vec<u32> {
    CLOCKS.with(|c| std::mem::take(&mut *c.borrow_mut()))
}

fn csd_read() -> Spi {
    [command(9, 0, R1_READY), data_block(&csd())].concat()
}

#[test]
fn missing_then_inserted_then_pulled() {
    let attempts = ACQUIRE_RETRIES as usize + 1;
    let expectations = [
        // 1. No card.
        silent_acquisition(attempts),
        // 2. A card: identified (with its size read), then the size asked.
        sdhc_identification(),
        csd_read(),
        csd_read(),
        // 3. Pulled during a block read: CMD17 gets no answer.
        byte(0xFF, NOTHING),
        send(17, 5),
        silence(POLLS_PER_COMMAND),
        // 4. The next access starts over with identification.
        silent_acquisition(attempts),
    ]
    .concat();
    let mut spi = Mock::new(&expectations);
    let card = Card::new(spi.clone(), NoopDelay::new(), set_clock, DATA_CLOCK_HZ);

    assert!(matches!(card.num_blocks(), Err(SdCardError::CardNotFound)));
    assert_eq!(take_clocks(), [IDENTIFICATION_CLOCK_HZ]);

    assert_eq!(card.num_blocks().ok(), Some(BlockCount(BLOCKS)));
    assert_eq!(take_clocks(), [IDENTIFICATION_CLOCK_HZ, DATA_CLOCK_HZ]);

    let mut block = [Block::new()];
    assert!(card.read(&mut block, BlockIdx(5)).is_err());
    assert_eq!(take_clocks(), []);

    assert!(matches!(card.num_blocks(), Err(SdCardError::CardNotFound)));
    assert_eq!(take_clocks(), [IDENTIFICATION_CLOCK_HZ]);
    spi.done();
}
