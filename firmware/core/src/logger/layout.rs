//! Where a card's first FAT16 or FAT32 volume keeps its FAT and its data,
//! read from the MBR and the boot sector (the FAT specification's BIOS
//! parameter block): the self-test counts free clusters with it, and the
//! logger checks that the blocks embedded-sdmmc gives its file lie inside
//! the data region (embedded-sdmmc 0.10 may allocate a cluster past the
//! last one of a full volume, `firmware/docs/hil.md`, known issues).

use embedded_sdmmc::{Block, BlockDevice, BlockIdx};

/// The layout of a FAT volume on 512-byte sectors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FatLayout {
    /// First block of the first FAT.
    pub fat_start: u32,
    /// Bytes per FAT entry: 2 (FAT16) or 4 (FAT32).
    pub entry_bytes: u32,
    /// Data clusters (numbered from 2).
    pub clusters: u32,
    /// Blocks per cluster.
    pub per_cluster: u32,
    /// First block of cluster 2.
    pub data_start: u32,
}

impl FatLayout {
    /// The layout of `card`'s first partition; `None` for anything but a
    /// FAT16 or FAT32 volume on 512-byte sectors whose FAT holds its
    /// clusters, or a card that cannot be read. Two block reads.
    pub fn of<D: BlockDevice>(card: &D) -> Option<Self> {
        let mut block = [Block::new()];
        let mut read = |idx: u32| -> Option<[u8; 512]> {
            card.read(&mut block, BlockIdx(idx)).ok()?;
            Some(block[0].contents)
        };
        // MBR: partition entry 0 at 446, its first block at +8.
        let mbr = read(0)?;
        let start = u32_at(&mbr, 446 + 8);
        let boot = read(start)?;
        let per_cluster = u32::from(boot[13]);
        if u16_at(&boot, 11) != 512 || per_cluster == 0 || boot[16] == 0 {
            return None;
        }
        // 16-bit fields where they are not 0, else their 32-bit FAT32
        // successors (section 3).
        let or32 = |small: u32, large: u32| if small != 0 { small } else { large };
        let fat_sectors = or32(u16_at(&boot, 22), u32_at(&boot, 36));
        let total = or32(u16_at(&boot, 19), u32_at(&boot, 32));
        let reserved = u16_at(&boot, 14);
        let root_sectors = (u16_at(&boot, 17) * 32).div_ceil(512);
        let meta = reserved
            .checked_add(u32::from(boot[16]).checked_mul(fat_sectors)?)?
            .checked_add(root_sectors)?;
        let clusters = total.checked_sub(meta)? / per_cluster;
        // The type follows from the cluster count alone (section 3.5).
        let entry_bytes: u32 = match clusters {
            0..4085 => return None,
            4085..65525 => 2,
            _ => 4,
        };
        if u64::from(clusters + 2) * u64::from(entry_bytes) > u64::from(fat_sectors) * 512 {
            return None;
        }
        Some(Self {
            fat_start: start.checked_add(reserved)?,
            entry_bytes,
            clusters,
            per_cluster,
            data_start: start.checked_add(meta)?,
        })
    }

    /// The block after the last data cluster's last block.
    #[must_use]
    pub fn data_end(&self) -> u32 {
        self.data_start
            .saturating_add(self.clusters.saturating_mul(self.per_cluster))
    }
}

/// The little-endian 16-bit field at `at`.
pub(crate) fn u16_at(b: &[u8; 512], at: usize) -> u32 {
    u32::from(u16::from_le_bytes([b[at], b[at + 1]]))
}

/// The little-endian 32-bit field at `at`.
pub(crate) fn u32_at(b: &[u8; 512], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}
