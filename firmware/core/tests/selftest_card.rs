//! The self-test's free-space figure comes from the FAT32 FSInfo sector of
//! the card's first partition: on a volume formatted by the `fatfs` crate it
//! agrees with that crate's own count, and anything but FAT32 gives none.

use std::io::Write;

use wobble_core::logger::mock::MockCard;
use wobble_core::selftest::fat32_free_mib;

const PART_START_BLOCKS: u64 = 2048;

/// A card of `mib` MiB with one FAT32 partition of `cluster_bytes`
/// clusters, and `fatfs`'s free count.
fn card(mib: u64, used_bytes: usize, cluster_bytes: u32) -> (Vec<u8>, u64) {
    let bytes = mib << 20;
    let mut image = vec![0u8; bytes as usize];
    let start = (PART_START_BLOCKS * 512) as usize;
    let blocks = (bytes / 512 - PART_START_BLOCKS) as u32;
    let opts = fatfs::FormatVolumeOptions::new()
        .fat_type(fatfs::FatType::Fat32)
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
    entry[4] = 0x0C;
    entry[8..12].copy_from_slice(&(PART_START_BLOCKS as u32).to_le_bytes());
    entry[12..16].copy_from_slice(&blocks.to_le_bytes());
    image[510] = 0x55;
    image[511] = 0xAA;
    (image, free)
}

#[test]
fn free_space_matches_the_file_systems_own_count() {
    // One sector a cluster and two (FAT32 needs 65 525 clusters, so larger
    // ones would need a larger image): the count is in clusters.
    for (used, cluster_bytes) in [(0, 512), (5 << 20, 512), (5 << 20, 1024)] {
        let (image, free_bytes) = card(128, used, cluster_bytes);
        let mib = fat32_free_mib(&MockCard::new(image)).expect("FAT32 count");
        assert_eq!(
            u64::from(mib),
            free_bytes >> 20,
            "used {used}, {cluster_bytes} B clusters"
        );
        assert!(mib > 100);
    }
}

#[test]
fn no_fat32_no_figure() {
    assert_eq!(fat32_free_mib(&MockCard::new(vec![0u8; 1 << 20])), None);
}

/// Each part of the FAT32 layout the figure rests on must be there: a
/// 512-byte sector, a cluster size, both FSInfo signatures and a known free
/// count (FAT32's "unknown" is 0xFFFFFFFF). Damaging any one of them
/// gives no figure.
#[test]
fn a_damaged_layout_gives_no_figure() {
    let (image, _) = card(128, 0, 512);
    let boot = (PART_START_BLOCKS * 512) as usize;
    let fsinfo_sector = u16::from_le_bytes([image[boot + 48], image[boot + 49]]) as usize;
    let fsinfo = boot + fsinfo_sector * 512;
    let damages: [(&str, usize, &[u8]); 5] = [
        ("1024-byte sectors", boot + 11, &1024u16.to_le_bytes()),
        ("no cluster size", boot + 13, &[0]),
        ("FSInfo lead signature", fsinfo, &[0; 4]),
        ("FSInfo structure signature", fsinfo + 484, &[0; 4]),
        ("unknown free count", fsinfo + 488, &[0xFF; 4]),
    ];
    for (what, at, bytes) in damages {
        let mut damaged = image.clone();
        damaged[at..at + bytes.len()].copy_from_slice(bytes);
        assert_eq!(fat32_free_mib(&MockCard::new(damaged)), None, "{what}");
    }
    assert!(fat32_free_mib(&MockCard::new(image)).is_some());
}
