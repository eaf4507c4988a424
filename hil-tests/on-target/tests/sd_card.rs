//! The card adapter on the real SPI2 with a FAT32 card: a file written,
//! flushed and read back through embedded-sdmmc, and a card pulled and
//! pushed back (by the person at the bench, within 20 s) identified again.
#![no_std]
#![no_main]

use defmt_rtt as _;

#[cfg(test)]
#[embedded_test::tests]
mod tests {
    use embassy_time::Duration;
    use embedded_sdmmc::{BlockDevice, Mode, VolumeIdx, VolumeManager};
    use wobble_core::logger::FixedTime;
    use wobble_on_target::{poll_until, sd_card as sd};

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
        let mut pulled = false;
        let back = poll_until(Duration::from_secs(20), Duration::from_millis(200), || {
            match (card.num_blocks().is_ok(), pulled) {
                (false, _) => pulled = true,
                (true, true) => return Some(()),
                (true, false) => {}
            }
            None
        })
        .await;
        if back.is_some() {
            return;
        }
        defmt::panic!("the card was not pulled and pushed back in time");
    }
}
