//! The card adapter on the real SPI2 with a FAT32 card: a file written,
//! flushed and read back through embedded-sdmmc, and a card pulled and
//! pushed back (by the person at the bench, within 20 s) identified again.
#![no_std]
#![no_main]

use defmt_rtt as _;

#[cfg(test)]
#[embedded_test::tests]
mod tests {
    use embassy_stm32::gpio::{Level, Output, Speed};
    use embassy_stm32::spi::Spi;
    use embassy_time::{Duration, Instant, Timer};
    use embedded_sdmmc::{BlockDevice, Mode, VolumeIdx, VolumeManager};
    use wobble_core::drivers::sdcard::IDENTIFICATION_CLOCK_HZ;
    use wobble_core::logger::FixedTime;
    use wobble_stm32f405::adapters::card::{self, SdCard};

    fn sd() -> SdCard {
        let (board, _) = wobble_on_target::board();
        let pins = board.card;
        let bus = Spi::new_blocking(
            pins.spi,
            pins.sck,
            pins.mosi,
            pins.miso,
            card::spi_config(IDENTIFICATION_CLOCK_HZ),
        );
        card::card(bus, Output::new(pins.cs, Level::High, Speed::VeryHigh))
    }

    #[test]
    fn a_file_is_written_flushed_and_read_back() {
        let volumes = VolumeManager::new(sd(), FixedTime::EPOCH);
        let volume = defmt::unwrap!(volumes.open_volume(VolumeIdx(0)).ok());
        let root = defmt::unwrap!(volume.open_root_dir().ok());
        let file = defmt::unwrap!(root
            .open_file_in_dir("ONTARGET.BIN", Mode::ReadWriteCreateOrTruncate)
            .ok());
        let block: [u8; 512] = core::array::from_fn(|i| i as u8);
        for _ in 0..64 {
            defmt::unwrap!(file.write(&block).ok());
        }
        defmt::unwrap!(file.flush().ok());
        defmt::assert_eq!(file.length(), 64 * 512);
        defmt::unwrap!(file.seek_from_start(0).ok());
        let mut back = [0u8; 512];
        for _ in 0..64 {
            defmt::assert_eq!(defmt::unwrap!(file.read(&mut back).ok()), 512);
            defmt::assert_eq!(back, block);
        }
    }

    #[test]
    #[timeout(40)]
    async fn a_card_pulled_and_pushed_back_is_identified_again() {
        let card = sd();
        defmt::assert!(card.num_blocks().is_ok(), "no card at the start");
        defmt::info!("pull the card out, then push it back in (20 s)");
        let until = Instant::now() + Duration::from_secs(20);
        let mut pulled = false;
        while Instant::now() < until {
            match (card.num_blocks().is_ok(), pulled) {
                (false, _) => pulled = true,
                (true, true) => return,
                (true, false) => {}
            }
            Timer::after_millis(200).await;
        }
        defmt::panic!("the card was not pulled and pushed back in time");
    }
}
