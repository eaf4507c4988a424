//! Cards as a rider buys and prepares them, made by the real tools
//! (`mkfs.fat` of dosfstools, `mkfs.exfat` of exfatprogs), on the logger's
//! card path (`wobble_core::logger`) and the self-test's free-space count
//! (`wobble_core::selftest::fat_free_mib`), through a block device that
//! reads and writes the image file itself (a 64 GB card stays sparse):
//! FAT32 of 512 B to 32 KiB clusters and FAT16 log, and `fsck.fat` finds
//! nothing wrong after; their free space is `fsck.fat`'s count; exFAT, on
//! its own or behind an MBR as SDXC cards ship, is an unusable card that is
//! never written; a full card is counted full.

use std::cell::{Cell, RefCell};
use std::fs::File;
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::Path;
use std::process::Command;

use embedded_sdmmc::{Block, BlockCount, BlockDevice, BlockIdx};
use wobble_core::format::{Frame, FrameStatus, Record};
use wobble_core::logger::{
    CardLogger, FixedTime, HeaderSpec, LoggerConfig, LoggerState, FAULT_CARD_FORMAT,
    FAULT_CARD_FULL,
};
use wobble_core::selftest::fat_free_mib;
use wobble_hil::qemu::card::{fill, fsck};

/// The image file as a card; counts the blocks written.
struct FileCard {
    file: RefCell<File>,
    writes: Cell<u32>,
}

impl FileCard {
    fn open(path: &Path) -> Self {
        let file = File::options().read(true).write(true).open(path).unwrap();
        Self {
            file: RefCell::new(file),
            writes: Cell::new(0),
        }
    }
}

impl BlockDevice for FileCard {
    type Error = std::io::Error;

    fn read(&self, blocks: &mut [Block], start: BlockIdx) -> Result<(), Self::Error> {
        let mut f = self.file.borrow_mut();
        f.seek(SeekFrom::Start(u64::from(start.0) * 512))?;
        for b in blocks {
            f.read_exact(&mut b.contents)?;
        }
        Ok(())
    }

    fn write(&self, blocks: &[Block], start: BlockIdx) -> Result<(), Self::Error> {
        let mut f = self.file.borrow_mut();
        f.seek(SeekFrom::Start(u64::from(start.0) * 512))?;
        for b in blocks {
            f.write_all(&b.contents)?;
            self.writes.set(self.writes.get() + 1);
        }
        Ok(())
    }

    fn num_blocks(&self) -> Result<BlockCount, Self::Error> {
        let len = self.file.borrow().metadata()?.len();
        Ok(BlockCount(u32::try_from(len / 512).unwrap_or(u32::MAX)))
    }
}

fn tool(name: &str, args: &[&str], path: &Path) {
    let out = Command::new(name)
        .args(args)
        .arg(path)
        .output()
        .unwrap_or_else(|e| panic!("{name}: {e} (hil-tests/install-tools.sh installs it)"));
    assert!(
        out.status.success(),
        "{name} {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A sparse image of `bytes` at `path`, formatted by `mkfs.fat` with `args`
/// and its one-partition MBR.
fn mkfs_fat(path: &Path, bytes: u64, args: &[&str]) {
    File::create(path).unwrap().set_len(bytes).unwrap();
    let mut all = vec!["-S", "512", "--mbr=y"];
    all.extend_from_slice(args);
    tool("mkfs.fat", &all, path);
}

/// Free clusters by `fsck.fat -n`'s summary (`N files, used/total
/// clusters`), in MiB of `cluster_bytes` clusters.
fn fsck_free_mib(path: &Path, cluster_bytes: u64) -> u64 {
    let report = fsck(path).unwrap();
    assert_eq!(report.code, 0, "{}", report.text);
    let summary = report
        .text
        .lines()
        .find(|l| l.contains(" clusters"))
        .unwrap_or_else(|| panic!("{}", report.text));
    let counts = summary.rsplit(", ").next().unwrap();
    let (used, total) = counts
        .trim_end_matches(" clusters")
        .split_once('/')
        .unwrap();
    let free = total.parse::<u64>().unwrap() - used.parse::<u64>().unwrap();
    (free * cluster_bytes) >> 20
}

type Logger<'a> = CardLogger<'a, FileCard, FixedTime>;

fn logger(path: &Path) -> Logger<'static> {
    let header = HeaderSpec {
        firmware: "test",
        device_id: [7; 12],
        sample_rate_hz: 100,
        config: &["sample_rate_hz=100"],
    };
    CardLogger::new(
        FileCard::open(path),
        FixedTime::EPOCH,
        header,
        LoggerConfig::DEFAULT,
    )
}

/// Logs frames `0..n` at 100 Hz as the writer does, then closes.
fn ride(log: &mut Logger<'_>, n: u64) {
    for i in 0..n {
        let now = i * 10_000;
        log.poll(now);
        let frame = Record::Frame(Frame {
            t_us: now,
            accel: [0, 0, 2048],
            gyro: [0; 3],
            steer_cdeg: (i % 300) as i16,
            wheel_count: i as u16,
            wheel_edge_age_us: 100,
            speed_mm_s: 4000,
            status: FrameStatus(0),
        });
        log.push(&frame, now);
    }
}

#[test]
fn fat16_and_fat32_cards_log_and_count_their_free_space() {
    let dir = tempfile::tempdir().unwrap();
    // (size, mkfs.fat options, cluster bytes): FAT32 of 512 B, 4 KiB and
    // 32 KiB clusters (the last on a 64 GB card, as SDXC sizes are), FAT16.
    let cases: [(u64, &[&str], u64); 4] = [
        (40 << 20, &["-F", "32", "-s", "1"], 512),
        (600 << 20, &["-F", "32", "-s", "8"], 4096),
        (64_000_000_000, &["-F", "32", "-s", "64"], 32_768),
        (256 << 20, &["-F", "16", "-s", "8"], 4096),
    ];
    for (bytes, args, cluster) in cases {
        let path = dir.path().join("card.img");
        mkfs_fat(&path, bytes, args);
        let free = fat_free_mib(&FileCard::open(&path)).expect("a FAT16 or FAT32 volume");
        assert_eq!(u64::from(free), fsck_free_mib(&path, cluster), "{args:?}");
        let mut log = logger(&path);
        ride(&mut log, 300);
        assert_eq!(log.state(), LoggerState::Logging { run: 1 }, "{args:?}");
        log.close(300 * 10_000).unwrap();
        drop(log);
        let report = fsck(&path).unwrap();
        assert!(report.problems().is_empty(), "{args:?}: {}", report.text);
        // Listed by fsck.fat (reading the files with `root_files` would
        // load a 64 GB image).
        let listing = Command::new("fsck.fat")
            .args(["-n", "-l"])
            .arg(&path)
            .output()
            .unwrap();
        let listing = String::from_utf8_lossy(&listing.stdout);
        assert!(listing.contains("/RUN00001.WBL"), "{args:?}: {listing}");
        std::fs::remove_file(&path).unwrap();
    }
}

#[test]
fn an_exfat_card_is_unusable_and_never_written() {
    let dir = tempfile::tempdir().unwrap();
    let bare = dir.path().join("exfat.img");
    File::create(&bare).unwrap().set_len(256 << 20).unwrap();
    tool("mkfs.exfat", &[], &bare);
    // As SDXC cards ship: an MBR whose partition (type 0x07) holds the
    // volume, from 1 MiB on.
    let behind_mbr = dir.path().join("sdxc.img");
    let volume = std::fs::read(&bare).unwrap();
    let mut image = vec![0u8; 1 << 20];
    image[446 + 4] = 0x07;
    image[446 + 8..446 + 12].copy_from_slice(&2048u32.to_le_bytes());
    let blocks = u32::try_from(volume.len() / 512).unwrap();
    image[446 + 12..446 + 16].copy_from_slice(&blocks.to_le_bytes());
    image[510] = 0x55;
    image[511] = 0xAA;
    image.extend_from_slice(&volume);
    std::fs::write(&behind_mbr, &image).unwrap();
    for path in [&bare, &behind_mbr] {
        let before = std::fs::read(path).unwrap();
        assert_eq!(fat_free_mib(&FileCard::open(path)), None);
        let mut log = logger(path);
        ride(&mut log, 250);
        assert_eq!(log.state(), LoggerState::UnusableCard);
        assert_eq!(log.stats().faults[usize::from(FAULT_CARD_FORMAT) - 1], 3);
        assert_eq!(log.with_device(|c| c.writes.get()), 0);
        drop(log);
        assert!(std::fs::read(path).unwrap() == before, "{}", path.display());
    }
}

#[test]
fn a_full_card_is_counted_full() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("card.img");
    mkfs_fat(&path, 40 << 20, &["-F", "32", "-s", "1"]);
    fill(&path, 3 << 20).unwrap();
    let nearly = fat_free_mib(&FileCard::open(&path)).unwrap();
    assert_eq!(u64::from(nearly), fsck_free_mib(&path, 512));
    assert!((2..=3).contains(&nearly), "{nearly} MiB");
    std::fs::remove_file(&path).unwrap();
    mkfs_fat(&path, 40 << 20, &["-F", "32", "-s", "1"]);
    fill(&path, 0).unwrap();
    assert_eq!(fat_free_mib(&FileCard::open(&path)), Some(0));
    // The filled volume's FSInfo says 0 free clusters while its FAT keeps
    // a few: embedded-sdmmc 0.10 then allocates one and decrements the
    // count below zero (`FatVolume::alloc_cluster`), a panic where overflow
    // is checked (these tests) and a wrap to "unknown" in the firmware's
    // release build. The hint is set to "unknown" here, as the wrap leaves
    // it; the card is full either way.
    let mut image = File::options().read(true).write(true).open(&path).unwrap();
    let mut boot = [0u8; 512];
    image.read_exact(&mut boot).unwrap();
    let fsinfo = u64::from(u16::from_le_bytes([boot[48], boot[49]]));
    image.seek(SeekFrom::Start(fsinfo * 512 + 488)).unwrap();
    image.write_all(&u32::MAX.to_le_bytes()).unwrap();
    drop(image);
    let mut log = logger(&path);
    ride(&mut log, 250);
    assert_ne!(log.state(), LoggerState::Logging { run: 1 });
    assert!(log.stats().faults[usize::from(FAULT_CARD_FULL) - 1] >= 1);
}
