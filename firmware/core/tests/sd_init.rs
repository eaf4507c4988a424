//! An SDHC card is identified with the SD spec's SPI-mode sequence: CMD0,
//! CMD59 (CRC on), CMD8, ACMD41 until ready, CMD58 (the wake-up clocks
//! before it: tests/sd_operation.rs).

mod sd_support;

use embedded_hal_mock::eh1::delay::NoopDelay;
use embedded_hal_mock::eh1::spi::Mock;
use embedded_sdmmc::embedded_sdmmc_types::sdcard::CardType;
use sd_support::*;
use wobble_core::drivers::sdcard::sd_card;

#[test]
fn command_crcs_match_the_spec_examples() {
    // The two commands sent before CRC checking is on must carry valid CRCs.
    assert_eq!(command_frame(0, 0), [0x40, 0, 0, 0, 0, 0x95]);
    assert_eq!(command_frame(8, 0x1AA), [0x48, 0, 0, 0x01, 0xAA, 0x87]);
}

#[test]
fn an_sdhc_card_is_identified() {
    let expectations = [
        // CMD0: the card answers on the second poll, idle.
        send(0, 0),
        byte(0xFF, NOTHING),
        byte(0xFF, R1_IDLE),
        command(59, 1, R1_IDLE),
        // CMD8: voltage accepted, check pattern echoed (SD v2).
        command(8, 0x1AA, R1_IDLE),
        tail([0x00, 0x00, 0x01, 0xAA]),
        // ACMD41 with HCS: still idle once, then ready.
        command(55, 0, R1_IDLE),
        command(41, 0x4000_0000, R1_IDLE),
        command(55, 0, R1_IDLE),
        command(41, 0x4000_0000, R1_READY),
        // CMD58: OCR with power-up done and CCS set: high capacity.
        command(58, 0, R1_READY),
        tail([0xC0, 0xFF, 0x80, 0x00]),
        byte(0xFF, NOTHING),
    ]
    .concat();
    let mut spi = Mock::new(&expectations);
    let card = sd_card(spi.clone(), NoopDelay::new());
    assert_eq!(card.get_card_type(), Some(CardType::SdhcSdxc));
    spi.done();
}
