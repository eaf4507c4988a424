//! The self-test's free-space figure is counted in the first FAT of the
//! card's first partition: on FAT16 and FAT32 volumes formatted and filled
//! by the `fatfs` crate it agrees with that crate's own count, a stale or
//! unknown FSInfo count does not change it, and a damaged layout gives none.

use std::io::Write;

use wobble_core::logger::mock::MockCard;
use wobble_core::selftest::fat_free_mib;

const PART_START_BLOCKS: u64 = 2048;

/// A card of `mib` MiB with one partition of `fat` and `cluster_bytes`
/// clusters holding a file of `used_bytes`, and `fatfs`'s free count.
fn card(mib: u64, fat: fatfs::FatType, used_bytes: usize, cluster_bytes: u32) -> (Vec<u8>, u64) {
    let bytes = mib << 20;
    let mut image = vec![0u8; bytes as usize];
    let start = (PART_START_BLOCKS * 512) as usize;
    let blocks = (bytes / 512 - PART_START_BLOCKS) as u32;
    let opts = fatfs::FormatVolumeOptions::new()
        .fat_type(fat)
        .bytes_per_cluster(cluster_bytes);
    fatfs::format_volume(std::io::Cursor::new(&mut image[start..]), opts).expect("format");
    let free = {
        let fs = fatfs::FileSystem::new(
            std::io::Cursor::new(&mut image[start..]),
            fatfs::FsOptions::new(),
        )
        .expect("mount");
        let mut f = fs.root_dir().create_file("RUN00001.WBL").expect("create");
        f.write_all(&vec![0xA5; used_bytes]).expect("write");
        drop(f);
        let stats = fs.stats().expect("stats");
        let free = stats.free_clusters() as u64 * stats.cluster_size() as u64;
        fs.unmount().expect("unmount");
        free
    };
    let entry = &mut image[446..462];
    entry[4] = if fat == fatfs::FatType::Fat32 {
        0x0C
    } else {
        0x0E
    };
    entry[8..12].copy_from_slice(&(PART_START_BLOCKS as u32).to_le_bytes());
    entry[12..16].copy_from_slice(&blocks.to_le_bytes());
    image[510] = 0x55;
    image[511] = 0xAA;
    (image, free)
}

#[test]
fn free_space_matches_the_file_systems_own_count() {
    use fatfs::FatType::{Fat16, Fat32};
    // FAT32 needs 65 525 clusters, so larger ones would need a larger
    // image; a full FAT16 card too.
    for (fat, used, cluster_bytes) in [
        (Fat32, 0, 512),
        (Fat32, 5 << 20, 512),
        (Fat32, 5 << 20, 1024),
        (Fat16, 0, 2048),
        (Fat16, 9 << 20, 2048),
        (Fat16, 100 << 20, 2048),
    ] {
        let (image, free_bytes) = card(128, fat, used, cluster_bytes);
        let mib = fat_free_mib(&MockCard::new(image)).expect("a count");
        assert_eq!(
            u64::from(mib),
            free_bytes >> 20,
            "{fat:?}, used {used}, {cluster_bytes} B clusters"
        );
    }
}

#[test]
fn no_fat_no_figure() {
    assert_eq!(fat_free_mib(&MockCard::new(vec![0u8; 1 << 20])), None);
}

/// FAT32's FSInfo count is a hint: unknown (0xFFFFFFFF), or stale after a
/// card was filled elsewhere, it changes nothing.
#[test]
fn the_fsinfo_hint_is_not_read() {
    let (image, free_bytes) = card(128, fatfs::FatType::Fat32, 5 << 20, 512);
    let boot = (PART_START_BLOCKS * 512) as usize;
    let fsinfo_sector = u16::from_le_bytes([image[boot + 48], image[boot + 49]]) as usize;
    let count = boot + fsinfo_sector * 512 + 488;
    for hint in [u32::MAX, 0, 7] {
        let mut stale = image.clone();
        stale[count..count + 4].copy_from_slice(&hint.to_le_bytes());
        assert_eq!(
            fat_free_mib(&MockCard::new(stale)).map(u64::from),
            Some(free_bytes >> 20),
            "hint {hint:#x}"
        );
    }
}

/// Each part of the layout the count rests on must be there: 512-byte
/// sectors, a cluster size, a FAT; a FAT that reaches past its sectors, or
/// a volume too small for FAT16, gives no figure either.
#[test]
fn a_damaged_layout_gives_no_figure() {
    let (image, _) = card(128, fatfs::FatType::Fat32, 0, 512);
    let boot = (PART_START_BLOCKS * 512) as usize;
    let damages: [(&str, usize, &[u8]); 5] = [
        ("1024-byte sectors", boot + 11, &1024u16.to_le_bytes()),
        ("no cluster size", boot + 13, &[0]),
        ("no FAT", boot + 16, &[0]),
        ("a FAT of one sector", boot + 36, &1u32.to_le_bytes()),
        (
            "a volume of 4000 sectors",
            boot + 32,
            &4000u32.to_le_bytes(),
        ),
    ];
    for (what, at, bytes) in damages {
        let mut damaged = image.clone();
        damaged[at..at + bytes.len()].copy_from_slice(bytes);
        assert_eq!(fat_free_mib(&MockCard::new(damaged)), None, "{what}");
    }
    assert!(fat_free_mib(&MockCard::new(image)).is_some());
}
