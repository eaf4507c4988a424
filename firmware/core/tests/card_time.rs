//! The files' time stamps: 2020-01-01 until the GPS has given UTC, then the
//! GPS's UTC (`logger::GpsTime`), in the directory entry that the flush
//! writes anyway.

mod card_support;
use card_support::{fat32_image, PART_START_BLOCKS};

use std::io::Read;
use std::sync::atomic::{AtomicU64, Ordering};

use embedded_sdmmc::{Mode, TimeSource, VolumeIdx, VolumeManager};
use wobble_core::channels::SharedStatus;
use wobble_core::format::UtcSync;
use wobble_core::logger::mock::MockCard;
use wobble_core::logger::{fat_timestamp, FixedTime, GpsTime};

const CARD_BYTES: u64 = 40 << 20;

static NOW_US: AtomicU64 = AtomicU64::new(0);

fn now_us() -> u64 {
    NOW_US.load(Ordering::Relaxed)
}

/// 2026-12-04 04:05:06 UTC, s since the Unix epoch.
const UTC_S: u64 = 1_796_357_106;

#[test]
fn calendar_of_unix_seconds() {
    let t = fat_timestamp(UTC_S).expect("in range");
    assert_eq!(
        (
            t.year_since_1970,
            t.zero_indexed_month,
            t.zero_indexed_day,
            t.hours,
            t.minutes,
            t.seconds
        ),
        (56, 11, 3, 4, 5, 6)
    );
    // 2000-02-29 23:59:59 (a leap day).
    let t = fat_timestamp(951_868_799).expect("in range");
    assert_eq!(
        (t.year_since_1970, t.zero_indexed_month, t.zero_indexed_day),
        (30, 1, 28)
    );
    assert!(fat_timestamp(0).is_none(), "1970 is before FAT's 1980");
}

/// Creates a file, writes a block and flushes; `between` runs (the GPS
/// gives UTC) and 25 s pass; another block and a flush. Returns the image
/// and the card writes of the second write and flush.
fn ride<T: TimeSource>(time: T, between: impl FnOnce()) -> (Vec<u8>, u32) {
    NOW_US.store(5_000_000, Ordering::Relaxed);
    let card = MockCard::new(fat32_image(CARD_BYTES, 512));
    let volumes: VolumeManager<_, _, 4, 4, 1> = VolumeManager::new(card, time);
    let volume = volumes.open_raw_volume(VolumeIdx(0)).expect("volume");
    let root = volumes.open_root_dir(volume).expect("root");
    let file = volumes
        .open_file_in_dir(root, "RUN00001.WBL", Mode::ReadWriteCreate)
        .expect("create");
    volumes.write(file, &[1u8; 512]).expect("write");
    volumes.flush_file(file).expect("flush");
    between();
    NOW_US.store(30_000_000, Ordering::Relaxed);
    let writes = volumes.device(|card| card.writes());
    volumes.write(file, &[2u8; 512]).expect("write");
    volumes.flush_file(file).expect("flush");
    let flush_writes = volumes.device(|card| card.writes()) - writes;
    volumes.close_file(file).expect("close");
    volumes.close_dir(root).expect("close dir");
    volumes.close_volume(volume).expect("close volume");
    let (card, _) = volumes.free();
    (card.image(), flush_writes)
}

#[test]
fn files_are_dated_from_the_gps_once_it_gave_utc() {
    static SHARED: SharedStatus = SharedStatus::new();
    let time = GpsTime::new(&SHARED, now_us);
    NOW_US.store(5_000_000, Ordering::Relaxed);
    assert_eq!(time.get_timestamp(), FixedTime::EPOCH.0);

    // The GPS gives UTC at 20 s after boot; the writer writes at 30 s.
    let (mut image, flush_writes) = ride(time, || {
        SHARED.set_utc(UtcSync {
            t_us: 20_000_000,
            unix_ms: (UTC_S - 10) * 1000 + 250,
        })
    });
    let start = (PART_START_BLOCKS * 512) as usize;
    let fs = fatfs::FileSystem::new(
        std::io::Cursor::new(&mut image[start..]),
        fatfs::FsOptions::new(),
    )
    .expect("mount");
    let entry = fs
        .root_dir()
        .iter()
        .map(|e| e.expect("entry"))
        .find(|e| e.short_file_name() == "RUN00001.WBL")
        .expect("the run file");
    let created = entry.created();
    assert_eq!(
        (created.date.year, created.date.month, created.date.day),
        (2020, 1, 1)
    );
    let modified = entry.modified();
    assert_eq!(
        (
            modified.date.year,
            modified.date.month,
            modified.date.day,
            modified.time.hour,
            modified.time.min,
            modified.time.sec
        ),
        (2026, 12, 4, 4, 5, 6)
    );
    let mut data = Vec::new();
    entry.to_file().read_to_end(&mut data).expect("read");
    assert_eq!(data.len(), 1024);
    // The time needs no write of its own: as many card writes as with the
    // fixed time.
    let (_, fixed_writes) = ride(FixedTime::EPOCH, || {});
    assert_eq!(flush_writes, fixed_writes);
}
