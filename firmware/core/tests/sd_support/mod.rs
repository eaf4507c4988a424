//! The SD card's SPI protocol as embedded-hal-mock transactions: one
//! chip-select frame per call the driver makes.
#![allow(dead_code)] // Each test file uses the helpers it needs.

use embedded_hal_mock::eh1::spi::Transaction;

pub type Spi = Vec<Transaction<u8>>;

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
