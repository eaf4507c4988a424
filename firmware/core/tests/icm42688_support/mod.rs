//! Transaction lists for the ICM-42688-P tests: how one register access
#![allow(dead_code)] // Each test file uses the helpers it needs.
//! looks on the SPI bus (one chip-select frame per access).

use embedded_hal_mock::eh1::spi::Transaction;
use wobble_core::drivers::icm42688::reg;

/// A register write: address byte (read bit clear), then the value.
pub fn write_reg(register: u8, value: u8) -> Vec<Transaction<u8>> {
    vec![
        Transaction::transaction_start(),
        Transaction::write_vec(vec![register, value]),
        Transaction::transaction_end(),
    ]
}

/// A burst read from `first`: address byte with the read bit, then the
/// sensor's answer.
pub fn read_regs(first: u8, answer: &[u8]) -> Vec<Transaction<u8>> {
    vec![
        Transaction::transaction_start(),
        Transaction::write_vec(vec![first | reg::READ]),
        Transaction::read_vec(answer.to_vec()),
        Transaction::transaction_end(),
    ]
}

/// One accel + gyro burst answering with these six words.
pub fn data_read(words: [i16; 6]) -> Vec<Transaction<u8>> {
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_be_bytes()).collect();
    read_regs(reg::ACCEL_DATA_X1, &bytes)
}
