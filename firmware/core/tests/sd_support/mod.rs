//! The SD card's SPI protocol as embedded-hal-mock transactions: one
//! chip-select frame per call the driver makes.
#![allow(dead_code)] // Each test file uses the helpers it needs.

use embedded_hal_mock::eh1::digital::{State, Transaction as Pin};
use embedded_hal_mock::eh1::spi::Transaction;
use wobble_core::drivers::sd_spi::WAKE_UP_BYTES;

pub type Spi = Vec<Transaction<u8>>;

/// The same exchange on the bus with chip select held by the device for
/// the whole operation: no frame per driver call.
pub fn held(device_level: Spi) -> Spi {
    let frame = [
        Transaction::transaction_start(),
        Transaction::transaction_end(),
    ];
    device_level
        .into_iter()
        .filter(|t| !frame.contains(t))
        .collect()
}

/// A card operation on the bus: `exchange` with chip select held, then the
/// operation's end (flush, CS high, one byte so the card releases MISO).
pub fn operation(exchange: Spi) -> Spi {
    let end = [
        Transaction::flush(),
        Transaction::write_vec(vec![0xFF]),
        Transaction::flush(),
    ];
    [held(exchange), end.to_vec()].concat()
}

/// The wake-up clocks before an identification (chip select high).
pub fn wake_up_clocks() -> Spi {
    vec![
        Transaction::write_vec(vec![0xFF; WAKE_UP_BYTES]),
        Transaction::flush(),
    ]
}

/// Chip-select pin levels, in order.
pub fn cs(levels: &[State]) -> Vec<Pin> {
    levels.iter().map(|&l| Pin::set(l)).collect()
}

/// Chip select around an identification: high for the wake-up clocks,
/// low for the operation, high after it.
pub const IDENTIFY_CS: [State; 3] = [State::High, State::Low, State::High];
/// Chip select around any other card operation.
pub const OPERATION_CS: [State; 2] = [State::Low, State::High];

/// R1 response: idle state (initialising).
pub const R1_IDLE: u8 = 0x01;
/// R1 response: ready.
pub const R1_READY: u8 = 0x00;
/// What a released MISO line reads: no card, or a card not answering.
pub const NOTHING: u8 = 0xFF;

/// CRC7 of a command (SD physical layer spec 4.5), polynomial x^7 + x^3 + 1.
pub fn crc7(bytes: &[u8]) -> u8 {
    let mut crc = 0u8;
    for &byte in bytes {
        for bit in (0..8).rev() {
            let feedback = ((byte >> bit) & 1) ^ (crc >> 6);
            crc = (crc << 1) & 0x7F;
            if feedback == 1 {
                crc ^= 0x09;
            }
        }
    }
    crc
}

/// The 6-byte command frame: start bits, index, argument, CRC7, end bit.
pub fn command_frame(index: u8, arg: u32) -> Vec<u8> {
    let mut frame = vec![0x40 | index];
    frame.extend(arg.to_be_bytes());
    frame.push((crc7(&frame) << 1) | 1);
    frame
}

/// One byte clocked out, `answer` clocked in.
pub fn byte(out: u8, answer: u8) -> Spi {
    vec![
        Transaction::transaction_start(),
        Transaction::transfer(vec![out], vec![answer]),
        Transaction::transaction_end(),
    ]
}

/// A command sent, without waiting for the card to be idle first (CMD0).
pub fn send(index: u8, arg: u32) -> Spi {
    vec![
        Transaction::transaction_start(),
        Transaction::write_vec(command_frame(index, arg)),
        Transaction::transaction_end(),
    ]
}

/// A command after the card reported not busy, answered with `r1`.
pub fn command(index: u8, arg: u32, r1: u8) -> Spi {
    [byte(0xFF, NOTHING), send(index, arg), byte(0xFF, r1)].concat()
}

/// Four more response bytes (R7 / R3 tails).
pub fn tail(answer: [u8; 4]) -> Spi {
    vec![
        Transaction::transaction_start(),
        Transaction::transfer_in_place(vec![0xFF; 4], answer.to_vec()),
        Transaction::transaction_end(),
    ]
}

/// CRC16 of a data block (SD spec 4.5: CCITT polynomial x^16 + x^12 + x^5 + 1).
pub fn crc16(bytes: &[u8]) -> u16 {
    let mut crc = 0u16;
    for &byte in bytes {
        crc ^= u16::from(byte) << 8;
        for _ in 0..8 {
            crc = if crc & 0x8000 != 0 {
                (crc << 1) ^ 0x1021
            } else {
                crc << 1
            };
        }
    }
    crc
}

/// A data block answered after its start token, with its CRC16.
pub fn data_block(data: &[u8]) -> Spi {
    data_block_with_crc(data, crc16(data))
}

/// A data block answered after its start token, with `crc`.
pub fn data_block_with_crc(data: &[u8], crc: u16) -> Spi {
    let mut out = byte(0xFF, 0xFE);
    out.extend([
        Transaction::transaction_start(),
        Transaction::transfer_in_place(vec![0xFF; data.len()], data.to_vec()),
        Transaction::transaction_end(),
        Transaction::transaction_start(),
        Transaction::transfer_in_place(vec![0xFF; 2], crc.to_be_bytes().to_vec()),
        Transaction::transaction_end(),
    ]);
    out
}

/// An SDHC card's identification: CMD0, CMD59, CMD8, ACMD41, CMD58.
pub fn sdhc_identification() -> Spi {
    [
        send(0, 0),
        byte(0xFF, R1_IDLE),
        command(59, 1, R1_IDLE),
        command(8, 0x1AA, R1_IDLE),
        tail([0x00, 0x00, 0x01, 0xAA]),
        command(55, 0, R1_IDLE),
        command(41, 0x4000_0000, R1_READY),
        command(58, 0, R1_READY),
        tail([0xC0, 0xFF, 0x80, 0x00]),
        byte(0xFF, NOTHING),
    ]
    .concat()
}

/// Response polls of one command before embedded-sdmmc times out: its
/// 10 000 retries (about 100 ms at 10 µs each) plus the first poll.
pub const POLLS_PER_COMMAND: usize = 10_001;
/// Bytes of 0xFF embedded-sdmmc clocks out after a CMD0 timeout.
pub const FLUSH_BYTES: usize = 255;

/// `n` polls that read nothing.
pub fn silence(n: usize) -> Spi {
    std::iter::repeat_with(|| byte(0xFF, NOTHING))
        .take(n)
        .flatten()
        .collect()
}

/// Acquisition of a card that never answers: `attempts` CMD0s, each polled
/// to the timeout and flushed, then the final byte.
pub fn silent_acquisition(attempts: usize) -> Spi {
    let attempt = || [send(0, 0), silence(POLLS_PER_COMMAND + FLUSH_BYTES)].concat();
    let mut out: Spi = std::iter::repeat_with(attempt)
        .take(attempts)
        .flatten()
        .collect();
    out.extend(silence(1));
    out
}
