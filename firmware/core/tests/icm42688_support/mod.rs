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

/// Reset values of the two filter-order registers (datasheet section 14).
const GYRO_CONFIG1_RESET: u8 = 0x16;
const ACCEL_CONFIG1_RESET: u8 = 0x0D;
const INT_CONFIG1_RESET: u8 = 0x10;

/// The bus traffic of `init`: identity check, reset, filters, ranges and
/// rate (`gyro_config0`, `accel_config0`), power.
pub fn init_sequence(gyro_config0: u8, accel_config0: u8) -> Vec<Transaction<u8>> {
    use reg::*;
    [
        write_reg(REG_BANK_SEL, 0),
        read_regs(WHO_AM_I, &[0x47]),
        write_reg(DEVICE_CONFIG, 0x01),
        // Bank 1, gyro AAF at 42 Hz: DELT 1, DELTSQR 1, BITSHIFT 15.
        write_reg(REG_BANK_SEL, 1),
        write_reg(GYRO_CONFIG_STATIC3, 1),
        write_reg(GYRO_CONFIG_STATIC4, 1),
        write_reg(GYRO_CONFIG_STATIC5, 0xF0),
        // Bank 2, accel AAF: DELT in bits 6:1, enable bit 0 clear.
        write_reg(REG_BANK_SEL, 2),
        write_reg(ACCEL_CONFIG_STATIC2, 0x02),
        write_reg(ACCEL_CONFIG_STATIC3, 1),
        write_reg(ACCEL_CONFIG_STATIC4, 0xF0),
        write_reg(REG_BANK_SEL, 0),
        write_reg(GYRO_CONFIG0, gyro_config0),
        write_reg(ACCEL_CONFIG0, accel_config0),
        // UI filter order 3rd (2) in bits 3:2 and 4:3, reserved bits kept.
        read_regs(GYRO_CONFIG1, &[GYRO_CONFIG1_RESET]),
        write_reg(GYRO_CONFIG1, 0x1A),
        read_regs(ACCEL_CONFIG1, &[ACCEL_CONFIG1_RESET]),
        write_reg(ACCEL_CONFIG1, 0x15),
        // Both UI bandwidths index 4: 400 Hz / 10.
        write_reg(GYRO_ACCEL_CONFIG0, 0x44),
        // FIFO: accel, gyro and temperature (packet 3), stream mode.
        write_reg(FIFO_CONFIG1, 0x07),
        write_reg(FIFO_CONFIG, 0x40),
        // INT1 pulsed, push-pull, active high, on data ready; the async
        // reset bit (1 at reset) cleared, the rest kept.
        write_reg(INT_CONFIG, 0x03),
        read_regs(INT_CONFIG1, &[INT_CONFIG1_RESET]),
        write_reg(INT_CONFIG1, 0x00),
        write_reg(INT_SOURCE0, 0x08),
        write_reg(PWR_MGMT0, 0x0F),
    ]
    .concat()
}
