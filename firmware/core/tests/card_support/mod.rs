//! Card images for the logger's tests, formatted by the `fatfs` crate (an
//! implementation independent of the logger's).
#![allow(dead_code)] // Each test file uses the helpers it needs.

use wobble_core::logger::HeaderSpec;

/// The header of a 100 Hz test logger with `config` lines.
pub fn header(config: &'static [&'static str]) -> HeaderSpec<'static> {
    HeaderSpec {
        firmware: "test",
        device_id: [7; 12],
        sample_rate_hz: 100,
        config,
    }
}

/// The partition starts at this block, after the MBR.
pub const PART_START_BLOCKS: u64 = 1;

/// A card image of `card_bytes`: an MBR with one FAT32 (LBA) partition from
/// [`PART_START_BLOCKS`] to the end, formatted with `cluster` bytes per
/// cluster.
pub fn fat32_image(card_bytes: u64, cluster: u32) -> Vec<u8> {
    let mut image = vec![0u8; card_bytes as usize];
    let start = (PART_START_BLOCKS * 512) as usize;
    let blocks = (card_bytes / 512 - PART_START_BLOCKS) as u32;
    let opts = fatfs::FormatVolumeOptions::new()
        .fat_type(fatfs::FatType::Fat32)
        .bytes_per_cluster(cluster);
    fatfs::format_volume(std::io::Cursor::new(&mut image[start..]), opts).expect("format");
    let entry = &mut image[446..462];
    entry[4] = 0x0C; // FAT32 with LBA addressing
    entry[8..12].copy_from_slice(&(PART_START_BLOCKS as u32).to_le_bytes());
    entry[12..16].copy_from_slice(&blocks.to_le_bytes());
    image[510] = 0x55;
    image[511] = 0xAA;
    image
}
