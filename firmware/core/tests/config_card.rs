//! `CONFIG.TXT` read from a FAT card: a file with a bad line, no file, no
//! file system, a file longer than the buffer, and a file whose second
//! block cannot be read.

use std::io::Write;

use embedded_sdmmc::VolumeManager;
use wobble_core::config::{load, Config, Source, FAULT_BAD_VALUE, FAULT_UNREADABLE, FILE_NAME};
use wobble_core::logger::mock::MockCard;
use wobble_core::logger::FixedTime;

/// A 4 MiB card: an MBR whose one partition (FAT16, LBA) starts at block 1,
/// holding `files`.
fn card(files: &[(&str, &[u8])]) -> MockCard {
    const BYTES: usize = 4 << 20;
    let mut image = vec![0u8; BYTES];
    let volume = &mut image[512..];
    // 512-byte clusters: 8 000 of them, a FAT16 volume by its cluster count.
    let options = fatfs::FormatVolumeOptions::new()
        .fat_type(fatfs::FatType::Fat16)
        .bytes_per_cluster(512);
    fatfs::format_volume(std::io::Cursor::new(&mut *volume), options).expect("format");
    {
        let fs = fatfs::FileSystem::new(std::io::Cursor::new(volume), fatfs::FsOptions::new())
            .expect("mount");
        for (name, data) in files {
            let mut file = fs.root_dir().create_file(name).expect("create");
            file.write_all(data).expect("write");
        }
    }
    let partition = [0x80, 0, 0, 0, 0x0E, 0, 0, 0];
    image[446..454].copy_from_slice(&partition);
    image[454..458].copy_from_slice(&1u32.to_le_bytes());
    image[458..462].copy_from_slice(&((BYTES / 512 - 1) as u32).to_le_bytes());
    image[510..512].copy_from_slice(&[0x55, 0xAA]);
    MockCard::new(image)
}

fn load_from(card: MockCard, buf_len: usize) -> (wobble_core::config::Loaded, Source) {
    let volumes = VolumeManager::new(card, FixedTime::EPOCH);
    let mut buf = vec![0u8; buf_len];
    let result = load(&volumes, &mut buf);
    assert!(!volumes.has_open_handles(), "everything closed again");
    result
}

#[test]
fn the_file_is_read_and_its_bad_lines_reported() {
    let text = b"wheel.holes=36\r\ndetector.amp_on_deg=lots\r\n";
    let (loaded, source) = load_from(card(&[(FILE_NAME, text)]), 4096);
    assert_eq!(source, Source::File);
    assert_eq!(loaded.config.wheel.holes, 36);
    assert_eq!(loaded.faults.count(FAULT_BAD_VALUE), 1);
}

#[test]
fn no_file_means_the_defaults_without_a_fault() {
    let (loaded, source) = load_from(card(&[("OTHER.TXT", b"wheel.holes=36\n")]), 4096);
    assert_eq!(source, Source::NoFile);
    assert_eq!(loaded.config, Config::default());
    assert!(loaded.faults.is_empty());
}

#[test]
fn a_blank_card_means_the_defaults() {
    let (loaded, source) = load_from(MockCard::new(vec![0u8; 1 << 20]), 4096);
    assert_eq!(source, Source::NoCard);
    assert_eq!(loaded.config, Config::default());
}

#[test]
fn a_file_longer_than_the_buffer_keeps_its_whole_lines() {
    // The first line fits; the second is cut by the 20-byte buffer.
    let text = b"wheel.holes=36\nwheel.timeout_us=900000\n";
    let (loaded, source) = load_from(card(&[(FILE_NAME, text)]), 20);
    assert_eq!(source, Source::File);
    assert_eq!(loaded.config.wheel.holes, 36);
    assert_eq!(
        loaded.config.wheel.timeout_us,
        Config::default().wheel.timeout_us
    );
    assert_eq!(loaded.faults.count(FAULT_UNREADABLE), 1);
    assert_eq!(loaded.faults.first().len(), 1);
}

#[test]
fn a_read_error_part_way_is_not_the_end_of_the_file() {
    // Block 1 of the file ends inside `wheel.circumference_m=2.135`, at
    // `2.1`; block 2 cannot be read. Taken as the end of the file, the cut
    // value would pass as a 2.1 m wheel, silently.
    let head = b"wheel.holes=36\n# padding\n";
    let key = b"wheel.circumference_m=2.1";
    let mut text = head.to_vec();
    // A comment line of padding up to the key.
    text.resize(512 - key.len() - 1, b'#');
    text.push(b'\n');
    text.extend_from_slice(key);
    assert_eq!(text.len(), 512);
    text.extend_from_slice(b"35\nwheel.timeout_us=900000\n");
    let card = card(&[(FILE_NAME, &text)]);
    let image = card.image();
    let second = image
        .windows(9)
        .position(|w| w == b"35\nwheel.")
        .expect("the file's second block");
    assert_eq!(second % 512, 0);
    card.set_unreadable(Some((second / 512) as u32));
    let (loaded, source) = load_from(card, 4096);
    assert_eq!(source, Source::File);
    assert_eq!(loaded.config.wheel.holes, 36);
    assert_eq!(
        loaded.config.wheel.circumference_m,
        Config::default().wheel.circumference_m
    );
    assert_eq!(loaded.faults.count(FAULT_UNREADABLE), 1);
}
