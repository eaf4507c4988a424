//! An hour of ride rewrites the card's shared sectors seldom: the root
//! directory's sector (which holds earlier rides' entries: a write torn by
//! a power cut could lose them) and FAT32's FSInfo sector, counted per card
//! block by a device under the logger. The logger writes zeros ahead of
//! its data and its data into them, so the entry, whose size covers the
//! zeros, needs a rewrite about once per `AHEAD_BLOCKS` blocks, not at
//! every flush. Both rides decode whole.

mod card_support;
use card_support::{fat32_image, header, read_file, ride, FRAME_PERIOD_US, PART_START_BLOCKS};

use std::cell::RefCell;
use std::collections::HashMap;

use embedded_sdmmc::{Block, BlockCount, BlockDevice, BlockIdx};
use wobble_core::format::{DecodeStats, Decoder, Event};
use wobble_core::logger::mock::{MockCard, MockError};
use wobble_core::logger::{CardLogger, FixedTime, LoggerConfig, LoggerState, AHEAD_BLOCKS};

const CONFIG: [&str; 1] = ["sample_rate_hz=100"];
const HOUR_FRAMES: u64 = 360_000;

/// A device that counts the writes to each card block.
struct Tally {
    card: MockCard,
    writes: RefCell<HashMap<u32, u32>>,
}

impl BlockDevice for Tally {
    type Error = MockError;

    fn read(&self, blocks: &mut [Block], start: BlockIdx) -> Result<(), MockError> {
        self.card.read(blocks, start)
    }

    fn write(&self, blocks: &[Block], start: BlockIdx) -> Result<(), MockError> {
        for i in 0..blocks.len() as u32 {
            *self.writes.borrow_mut().entry(start.0 + i).or_default() += 1;
        }
        self.card.write(blocks, start)
    }

    fn num_blocks(&self) -> Result<BlockCount, MockError> {
        self.card.num_blocks()
    }
}

/// The card blocks of the root directory's first sector and of FSInfo, from
/// the FAT32 boot sector.
fn shared_sectors(image: &[u8]) -> (u32, u32) {
    let boot = (PART_START_BLOCKS * 512) as usize;
    let u16_at = |o: usize| u32::from(u16::from_le_bytes([image[boot + o], image[boot + o + 1]]));
    let u32_at = |o: usize| u32::from_le_bytes(image[boot + o..boot + o + 4].try_into().unwrap());
    let part = PART_START_BLOCKS as u32;
    let (reserved, fats, fat_size) = (u16_at(14), u32::from(image[boot + 16]), u32_at(36));
    let per_cluster = u32::from(image[boot + 13]);
    let root = part + reserved + fats * fat_size + (u32_at(44) - 2) * per_cluster;
    (root, part + u16_at(48))
}

/// A ride of `frames` frames at 100 Hz with a 20 Hz GPS, each record
/// polled and pushed as the writer does with no backlog; returns the time
/// after the last.
fn ride_into(log: &mut CardLogger<'_, Tally, FixedTime>, frames: u64) -> u64 {
    for (t, rec) in ride(frames) {
        log.poll(t);
        log.write_ahead(t);
        log.push(&rec, t);
    }
    frames * FRAME_PERIOD_US
}

fn decoded(file: &[u8]) -> DecodeStats {
    let mut dec = Decoder::new();
    dec.feed(file, true, &mut |_: Event<'_>| {});
    *dec.stats()
}

#[test]
fn an_hour_rewrites_the_directory_and_fsinfo_sectors_seldom() {
    let image = fat32_image(64 << 20, 512);
    let (root, fsinfo) = shared_sectors(&image);
    let device = Tally {
        card: MockCard::new(image),
        writes: RefCell::new(HashMap::new()),
    };
    let mut log = CardLogger::new(
        device,
        FixedTime::EPOCH,
        header(&CONFIG),
        LoggerConfig::DEFAULT,
    );
    // An earlier ride of a minute, closed: its entry shares the sector.
    let t = ride_into(&mut log, 6_000);
    log.close(t).expect("closed");
    let mut log = CardLogger::new(
        log.into_device(),
        FixedTime::EPOCH,
        header(&CONFIG),
        LoggerConfig::DEFAULT,
    );
    log.with_device(|d| d.writes.borrow_mut().clear());
    let end = ride_into(&mut log, HOUR_FRAMES);
    assert_eq!(log.state(), LoggerState::Logging { run: 2 });
    let stats = log.stats();
    let tally = |log: &CardLogger<'_, Tally, FixedTime>, block: u32| {
        log.with_device(|d| d.writes.borrow().get(&block).copied().unwrap_or(0))
    };
    let (dir, info) = (tally(&log, root), tally(&log, fsinfo));
    println!(
        "FIGURES an hour at 100 Hz with 20 Hz GPS: {} flushes, {} entry rewrites; root directory \
         sector written {dir} times, FSInfo {info} times; {} blocks of zeros written ahead",
        stats.flushes, stats.entry_writes, stats.ahead_writes
    );
    // A flush every 500 ms: 7200 an hour, each of which used to rewrite
    // both sectors.
    assert!(stats.flushes >= 7_190, "{stats:?}");
    // The entry at the file's creation and as the data nears its size.
    assert!(dir <= stats.entry_writes + 2, "{dir} {stats:?}");
    assert!(info <= stats.entry_writes + 2, "{info} {stats:?}");
    assert!(stats.entry_writes <= 120, "{stats:?}");
    assert_eq!(stats.frames_lost, 0);

    // The card as a power cut now would leave it: the earlier ride whole,
    // this one to its last flush (the size covers it), the zeros ahead
    // counted as unwritten.
    let image = log.with_device(|d| d.card.image());
    let first = decoded(&read_file(&image, "RUN00001.WBL").expect("first ride"));
    assert_eq!(
        (first.frames, first.bytes_skipped, first.blocks_lost),
        (6_000, 0, 0)
    );
    let second = decoded(&read_file(&image, "RUN00002.WBL").expect("second ride"));
    assert_eq!(second.frames, u64::from(stats.frames_on_card));
    assert!(second.frames + 50 >= HOUR_FRAMES, "{second:?}");
    assert_eq!((second.bytes_skipped, second.blocks_lost), (0, 0));
    assert!(
        second.unwritten_blocks <= u64::from(AHEAD_BLOCKS),
        "{second:?}"
    );
    // Closed: every frame.
    log.close(end).expect("closed");
    let image = log.into_device().card.image();
    let second = decoded(&read_file(&image, "RUN00002.WBL").expect("second ride"));
    assert_eq!((second.frames, second.bytes_skipped), (HOUR_FRAMES, 0));
}
