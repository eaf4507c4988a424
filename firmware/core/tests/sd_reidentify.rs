//! The card block device identifies a card (wake-up clocks, slow clock),
//! runs it at the data clock with chip select held for each operation, and
//! after any error identifies it again before the next access: a card that
//! was missing, then inserted, then pulled; and one whose blocks keep
//! failing their CRC, read or written, which then runs at half the clock
//! (a pulled card's unanswered write does not count) until clean transfers
//! or a card identified after removal bring it back.

mod sd_support;

use std::cell::{Cell, RefCell};

use embedded_hal_mock::eh1::delay::NoopDelay;
use embedded_hal_mock::eh1::digital::{Mock as PinMock, State};
use embedded_hal_mock::eh1::spi::{Mock, Transaction};
use embedded_sdmmc::{Block, BlockCount, BlockDevice, BlockIdx, SdCardError};
use sd_support::*;
use wobble_core::drivers::sdcard::{
    Card, CardHooks, ACQUIRE_RETRIES, CLEAN_TRANSFERS_BEFORE_RAISING, CRC_ERRORS_BEFORE_SLOWING,
    IDENTIFICATION_CLOCK_HZ,
};

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
    static OPERATIONS: Cell<u32> = const { Cell::new(0) };
}

fn set_clock(_: &mut Mock<u8>, hz: u32) {
    CLOCKS.with(|c| c.borrow_mut().push(hz));
}

fn take_clocks() -> Vec<u32> {
    CLOCKS.with(|c| std::mem::take(&mut *c.borrow_mut()))
}

fn count_operation() {
    OPERATIONS.with(|n| n.set(n.get() + 1));
}

pub const HOOKS: CardHooks<Mock<u8>> = CardHooks {
    set_clock,
    now_us: || 0,
    after_operation: count_operation,
};

/// The card under test on (clones of) the mocks.
fn card(spi: &Mock<u8>, cs: &PinMock) -> Card<Mock<u8>, PinMock, NoopDelay> {
    Card::new(
        spi.clone(),
        cs.clone(),
        NoopDelay::new(),
        HOOKS,
        DATA_CLOCK_HZ,
    )
}

fn csd_read() -> Spi {
    [command(9, 0, R1_READY), data_block(&csd())].concat()
}

/// Wake-up clocks, then `exchange` as one operation.
fn identification(exchange: Spi) -> Spi {
    [wake_up_clocks(), operation(exchange)].concat()
}

#[test]
fn missing_then_inserted_then_pulled() {
    let attempts = ACQUIRE_RETRIES as usize + 1;
    let expectations = [
        // 1. No card.
        identification(silent_acquisition(attempts)),
        // 2. A card: identified (with its size read), then the size asked.
        identification([sdhc_identification(), csd_read()].concat()),
        operation(csd_read()),
        // 3. Pulled during a block read: CMD17 gets no answer.
        operation([byte(0xFF, NOTHING), send(17, 5), silence(POLLS_PER_COMMAND)].concat()),
        // 4. The next access starts over, wake-up clocks first.
        identification(silent_acquisition(attempts)),
    ]
    .concat();
    let mut spi = Mock::new(&expectations);
    let pins = [
        &IDENTIFY_CS[..],
        &IDENTIFY_CS,
        &OPERATION_CS,
        &OPERATION_CS,
        &IDENTIFY_CS,
    ]
    .concat();
    let mut chip_select = PinMock::new(&cs(&pins));
    let card = card(&spi, &chip_select);

    assert!(matches!(card.num_blocks(), Err(SdCardError::CardNotFound)));
    assert_eq!(take_clocks(), [IDENTIFICATION_CLOCK_HZ]);

    assert_eq!(card.num_blocks().ok(), Some(BlockCount(BLOCKS)));
    assert_eq!(take_clocks(), [IDENTIFICATION_CLOCK_HZ, DATA_CLOCK_HZ]);

    let mut block = [Block::new()];
    assert!(card.read(&mut block, BlockIdx(5)).is_err());
    assert_eq!(take_clocks(), []);

    assert!(matches!(card.num_blocks(), Err(SdCardError::CardNotFound)));
    assert_eq!(take_clocks(), [IDENTIFICATION_CLOCK_HZ]);
    // Every operation, failed or not, proved the writer alive.
    assert_eq!(OPERATIONS.with(Cell::get), 5);
    spi.done();
    chip_select.done();
}

#[test]
fn repeated_crc_errors_halve_the_data_clock() {
    let block = [0x5Au8; 512];
    let bad_read = || {
        [
            command(17, 9, R1_READY),
            data_block_with_crc(&block, crc16(&block) ^ 1),
        ]
        .concat()
    };
    let identify = || identification([sdhc_identification(), csd_read()].concat());
    let mut expectations = Vec::new();
    let mut pins = Vec::new();
    for _ in 0..CRC_ERRORS_BEFORE_SLOWING {
        expectations.extend([identify(), operation(bad_read())].concat());
        pins.extend([&IDENTIFY_CS[..], &OPERATION_CS].concat());
    }
    expectations.extend(
        [
            identify(),
            operation([command(17, 9, R1_READY), data_block(&block)].concat()),
        ]
        .concat(),
    );
    pins.extend([&IDENTIFY_CS[..], &OPERATION_CS].concat());
    let mut spi = Mock::new(&expectations);
    let mut chip_select = PinMock::new(&cs(&pins));
    let card = card(&spi, &chip_select);
    let mut blocks = [Block::new()];
    for _ in 0..CRC_ERRORS_BEFORE_SLOWING {
        let read = card.read(&mut blocks, BlockIdx(9));
        assert!(matches!(read, Err(SdCardError::CrcError(..))), "{read:?}");
    }
    assert_eq!(card.data_clock_hz(), DATA_CLOCK_HZ / 2);
    card.read(&mut blocks, BlockIdx(9))
        .expect("read at the lower clock");
    assert_eq!(blocks[0].contents, block);
    let clocks = take_clocks();
    let data_clocks: Vec<u32> = clocks
        .into_iter()
        .filter(|&hz| hz != IDENTIFICATION_CLOCK_HZ)
        .collect();
    assert_eq!(
        data_clocks,
        [
            DATA_CLOCK_HZ,
            DATA_CLOCK_HZ,
            DATA_CLOCK_HZ,
            DATA_CLOCK_HZ / 2
        ]
    );
    spi.done();
    chip_select.done();
}

/// Bytes written in one transaction of their own.
fn written(bytes: &[u8]) -> Spi {
    vec![
        Transaction::transaction_start(),
        Transaction::write_vec(bytes.to_vec()),
        Transaction::transaction_end(),
    ]
}

/// A block write reaches the card whole: CMD24 at the block's index (an
/// SDHC card counts blocks), the start token, the 512 bytes and their
/// CRC16, then the card's acceptance, its busy time and its status.
#[test]
fn a_written_block_reaches_the_card_whole() {
    let mut block = Block::new();
    for (i, b) in block.contents.iter_mut().enumerate() {
        *b = (i * 7) as u8;
    }
    let data_accepted = 0x05;
    let expectations = [
        identification([sdhc_identification(), csd_read()].concat()),
        operation(
            [
                command(24, 42, R1_READY),
                byte(0xFE, NOTHING),
                written(&block.contents),
                written(&crc16(&block.contents).to_be_bytes()),
                byte(0xFF, data_accepted),
                // Busy for a while, then free.
                byte(0xFF, 0x00),
                byte(0xFF, 0x00),
                byte(0xFF, NOTHING),
                command(13, 0, R1_READY),
                byte(0xFF, 0x00),
            ]
            .concat(),
        ),
    ]
    .concat();
    let mut spi = Mock::new(&expectations);
    let mut chip_select = PinMock::new(&cs(&[&IDENTIFY_CS[..], &OPERATION_CS].concat()));
    let card = card(&spi, &chip_select);
    card.write(&[block], BlockIdx(42)).expect("written");
    spi.done();
    chip_select.done();
}

/// A card that keeps rejecting written blocks' CRC (data response token
/// 0x0B, which embedded-sdmmc 0.10 reports as a write error) runs at half
/// the clock too: the signal is as bad going out as coming in.
#[test]
fn repeated_write_crc_rejections_halve_the_data_clock() {
    let block = Block::new();
    let (expectations, pins) = crc_rejections(&block);
    let mut spi = Mock::new(&expectations);
    let mut chip_select = PinMock::new(&cs(&pins));
    let card = card(&spi, &chip_select);
    for _ in 0..CRC_ERRORS_BEFORE_SLOWING {
        let write = card.write(std::slice::from_ref(&block), BlockIdx(42));
        assert!(matches!(write, Err(SdCardError::WriteError)), "{write:?}");
    }
    assert_eq!(card.data_clock_hz(), DATA_CLOCK_HZ / 2);
    spi.done();
    chip_select.done();
}

/// A block write answered by nothing: the data response reads 0xFF, as
/// from a pulled card (MISO pulled up).
fn unanswered_write(block: &Block) -> Spi {
    [
        command(24, 42, R1_READY),
        byte(0xFE, NOTHING),
        written(&block.contents),
        written(&crc16(&block.contents).to_be_bytes()),
        byte(0xFF, NOTHING),
    ]
    .concat()
}

/// A written block accepted, then the card free and its status clean.
fn accepted_write(block: &Block) -> Spi {
    [
        command(24, 42, R1_READY),
        byte(0xFE, NOTHING),
        written(&block.contents),
        written(&crc16(&block.contents).to_be_bytes()),
        byte(0xFF, 0x05),
        byte(0xFF, NOTHING),
        command(13, 0, R1_READY),
        byte(0xFF, 0x00),
    ]
    .concat()
}

/// The card's side of [`CRC_ERRORS_BEFORE_SLOWING`] writes of `block`, each
/// after an identification, that the card rejects for their CRC (what
/// slows the clock), and the chip-select levels they take.
fn crc_rejections(block: &Block) -> (Spi, Vec<State>) {
    let identify = || identification([sdhc_identification(), csd_read()].concat());
    let mut expectations = Vec::new();
    let mut pins = Vec::new();
    for _ in 0..CRC_ERRORS_BEFORE_SLOWING {
        expectations.extend([identify(), operation(crc_rejected_write(block))].concat());
        pins.extend([&IDENTIFY_CS[..], &OPERATION_CS].concat());
    }
    (expectations, pins)
}

/// A block write the card rejects for its CRC (data response 0x0B).
fn crc_rejected_write(block: &Block) -> Spi {
    [
        command(24, 42, R1_READY),
        byte(0xFE, NOTHING),
        written(&block.contents),
        written(&crc16(&block.contents).to_be_bytes()),
        byte(0xFF, 0x0B),
    ]
    .concat()
}

/// A card pulled during writes (and pushed back each time) leaves the clock
/// alone: its write errors are not CRC errors.
#[test]
fn a_pulled_cards_write_errors_do_not_slow_the_clock() {
    let block = Block::new();
    let identify = || identification([sdhc_identification(), csd_read()].concat());
    let mut expectations = Vec::new();
    let mut pins = Vec::new();
    for _ in 0..CRC_ERRORS_BEFORE_SLOWING + 1 {
        expectations.extend([identify(), operation(unanswered_write(&block))].concat());
        pins.extend([&IDENTIFY_CS[..], &OPERATION_CS].concat());
    }
    let mut spi = Mock::new(&expectations);
    let mut chip_select = PinMock::new(&cs(&pins));
    let card = card(&spi, &chip_select);
    for _ in 0..CRC_ERRORS_BEFORE_SLOWING + 1 {
        let write = card.write(std::slice::from_ref(&block), BlockIdx(42));
        assert!(matches!(write, Err(SdCardError::WriteError)), "{write:?}");
    }
    assert_eq!(card.data_clock_hz(), DATA_CLOCK_HZ);
    take_clocks();
    spi.done();
    chip_select.done();
}

/// After the clock was lowered, enough clean transfers in a row bring it
/// back up to the nominal clock.
#[test]
fn clean_transfers_restore_the_data_clock() {
    let block = Block::new();
    let identify = || identification([sdhc_identification(), csd_read()].concat());
    let (mut expectations, mut pins) = crc_rejections(&block);
    expectations.extend(identify());
    pins.extend(IDENTIFY_CS);
    for _ in 0..CLEAN_TRANSFERS_BEFORE_RAISING {
        expectations.extend(operation(accepted_write(&block)));
        pins.extend(OPERATION_CS);
    }
    let mut spi = Mock::new(&expectations);
    let mut chip_select = PinMock::new(&cs(&pins));
    let card = card(&spi, &chip_select);
    for _ in 0..CRC_ERRORS_BEFORE_SLOWING {
        assert!(card
            .write(std::slice::from_ref(&block), BlockIdx(42))
            .is_err());
    }
    assert_eq!(card.data_clock_hz(), DATA_CLOCK_HZ / 2);
    take_clocks();
    for i in 0..CLEAN_TRANSFERS_BEFORE_RAISING {
        assert_eq!(
            card.data_clock_hz(),
            DATA_CLOCK_HZ / 2,
            "after {i} clean writes"
        );
        card.write(std::slice::from_ref(&block), BlockIdx(42))
            .expect("written");
    }
    assert_eq!(card.data_clock_hz(), DATA_CLOCK_HZ);
    assert_eq!(
        take_clocks(),
        [IDENTIFICATION_CLOCK_HZ, DATA_CLOCK_HZ / 2, DATA_CLOCK_HZ]
    );
    spi.done();
    chip_select.done();
}

/// A slowed card pulled and a card identified in its place runs at the
/// nominal clock again.
#[test]
fn a_card_identified_after_removal_runs_at_the_nominal_clock() {
    let block = Block::new();
    let identify = || identification([sdhc_identification(), csd_read()].concat());
    let (mut expectations, mut pins) = crc_rejections(&block);
    expectations.extend([identify(), operation(unanswered_write(&block))].concat());
    pins.extend([&IDENTIFY_CS[..], &OPERATION_CS].concat());
    expectations.extend([identify(), operation(csd_read())].concat());
    pins.extend([&IDENTIFY_CS[..], &OPERATION_CS].concat());
    let mut spi = Mock::new(&expectations);
    let mut chip_select = PinMock::new(&cs(&pins));
    let card = card(&spi, &chip_select);
    for _ in 0..=CRC_ERRORS_BEFORE_SLOWING {
        assert!(card
            .write(std::slice::from_ref(&block), BlockIdx(42))
            .is_err());
    }
    assert_eq!(card.data_clock_hz(), DATA_CLOCK_HZ / 2);
    take_clocks();
    assert_eq!(card.num_blocks().ok(), Some(BlockCount(BLOCKS)));
    assert_eq!(card.data_clock_hz(), DATA_CLOCK_HZ);
    assert_eq!(take_clocks(), [IDENTIFICATION_CLOCK_HZ, DATA_CLOCK_HZ]);
    spi.done();
    chip_select.done();
}
