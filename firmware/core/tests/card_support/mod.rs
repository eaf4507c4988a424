//! Card images for the logger's tests, formatted by the `fatfs` crate (an
//! implementation independent of the logger's).
#![allow(dead_code)] // Each test file uses the helpers it needs.

use wobble_core::format::{Frame, FrameStatus, GpsFix, Record};
use wobble_core::logger::HeaderSpec;

/// Frames 10 ms apart.
pub const FRAME_PERIOD_US: u64 = 10_000;

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

/// Runs `f` on the FAT volume of `image` (mounted by `fatfs`).
pub fn with_fs<R>(
    image: &mut [u8],
    f: impl FnOnce(&fatfs::FileSystem<std::io::Cursor<&mut [u8]>>) -> R,
) -> R {
    let start = (PART_START_BLOCKS * 512) as usize;
    let fs = fatfs::FileSystem::new(
        std::io::Cursor::new(&mut image[start..]),
        fatfs::FsOptions::new(),
    )
    .expect("mount");
    f(&fs)
}

/// The contents of a file, as the directory entry's size says.
pub fn read_file(image: &[u8], name: &str) -> Option<Vec<u8>> {
    use std::io::Read;
    let mut image = image.to_vec();
    with_fs(&mut image, |fs| {
        let mut file = fs.root_dir().open_file(name).ok()?;
        let mut data = Vec::new();
        file.read_to_end(&mut data).ok()?;
        Some(data)
    })
}

/// Fills the card but `free_bytes` with a file.
pub fn fill_card(image: &mut [u8], free_bytes: u64) {
    use std::io::{Seek, SeekFrom, Write};
    with_fs(image, |fs| {
        let stats = fs.stats().expect("stats");
        let free = stats.free_clusters() as u64 * stats.cluster_size() as u64;
        let mut file = fs.root_dir().create_file("FILLER.BIN").expect("create");
        let chunk = vec![0xA5u8; 1 << 16];
        let mut left = free - free_bytes;
        while left > 0 {
            let n = left.min(chunk.len() as u64) as usize;
            file.write_all(&chunk[..n]).expect("fill");
            left -= n as u64;
        }
        file.flush().expect("flush");
        file.seek(SeekFrom::Start(0)).expect("seek");
    });
}

/// Frame `i` of a test ride (every channel moving).
pub fn frame(i: u64) -> Record<'static> {
    Record::Frame(Frame {
        t_us: i * FRAME_PERIOD_US,
        accel: [i as i16, (i % 1000) as i16 - 500, 2048],
        gyro: [(i % 97) as i16, 2, 3],
        steer_cdeg: (i % 300) as i16,
        wheel_count: i as u16,
        wheel_edge_age_us: 100,
        speed_mm_s: 4000,
        status: FrameStatus(0),
    })
}

pub fn fix(i: u64) -> Record<'static> {
    Record::Gps(GpsFix {
        t_us: i * FRAME_PERIOD_US,
        lat_e7: Some(520_000_000 + i as i32),
        lon_e7: Some(43_000_000 - i as i32),
        ..GpsFix::default()
    })
}

/// The records of `frames` frames at 100 Hz with a 20 Hz GPS, with their
/// times: what the writer drains.
pub fn ride(frames: u64) -> impl Iterator<Item = (u64, Record<'static>)> {
    (0..frames).flat_map(|i| {
        let t = i * FRAME_PERIOD_US;
        let gps = (i % 5 == 0).then(|| (t, fix(i)));
        core::iter::once((t, frame(i))).chain(gps)
    })
}
