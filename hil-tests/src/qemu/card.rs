//! The card image on the host: made with `mkfs.fat`, checked with
//! `fsck.fat -n`, read with the `fatfs` crate.

use std::io::Read;
use std::path::Path;
use std::process::Command;

/// Card size: FAT32 with 512-byte clusters needs at least 65 525 clusters
/// (32 MiB); 40 MiB leaves room and stays quick to copy.
pub const CARD_BYTES: u64 = 40 << 20;

/// Creates a fresh FAT32 image at `path` with an MBR partition table (the
/// layout of an SD card, which embedded-sdmmc requires).
///
/// # Errors
/// `mkfs.fat` is missing or failed.
pub fn mkfs(path: &Path) -> Result<(), String> {
    let file = std::fs::File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
    file.set_len(CARD_BYTES)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    drop(file);
    let out = Command::new("mkfs.fat")
        .args([
            "-F", "32", "-S", "512", "-s", "1", "--mbr=y", "-n", "WOBBLE",
        ])
        .arg(path)
        .output()
        .map_err(|e| format!("mkfs.fat: {e} (install dosfstools)"))?;
    if out.status.success() {
        Ok(())
    } else {
        Err(format!(
            "mkfs.fat failed: {}",
            String::from_utf8_lossy(&out.stderr)
        ))
    }
}

/// What `fsck.fat -n` said.
#[derive(Clone, Debug)]
pub struct Fsck {
    /// Its exit code: 0 clean, 1 errors found (and not fixed: `-n`).
    pub code: i32,
    /// Its output, stdout then stderr.
    pub text: String,
}

impl Fsck {
    /// The complaints, one per line, without the banner and the summary.
    #[must_use]
    pub fn problems(&self) -> Vec<String> {
        self.text
            .lines()
            .map(str::trim)
            .filter(|l| {
                !l.is_empty()
                    && !l.starts_with("fsck.fat ")
                    && !l.contains(" files, ")
                    && !l.starts_with("Leaving filesystem unchanged")
                    && !l.starts_with("There are differences between boot sector")
                    && !l.starts_with("Not automatically fixing")
            })
            .map(str::to_owned)
            .collect()
    }
}

/// Runs `fsck.fat -n` (check only, change nothing) on the image.
///
/// # Errors
/// `fsck.fat` is missing.
pub fn fsck(path: &Path) -> Result<Fsck, String> {
    let out = Command::new("fsck.fat")
        .arg("-n")
        .arg(path)
        .output()
        .map_err(|e| format!("fsck.fat: {e} (install dosfstools)"))?;
    Ok(Fsck {
        code: out.status.code().unwrap_or(-1),
        text: format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ),
    })
}

/// The mounted volume of a card image held in memory.
type Volume<'a> = fatfs::FileSystem<std::io::Cursor<&'a mut [u8]>>;

/// Runs `f` on the FAT volume of the image `bytes` (changes stay in `bytes`).
fn with_volume<R>(
    bytes: &mut [u8],
    f: impl FnOnce(&Volume<'_>) -> Result<R, String>,
) -> Result<R, String> {
    let start = partition_start(bytes).ok_or("no MBR partition")?;
    let part = bytes
        .get_mut(start..)
        .ok_or("partition outside the image")?;
    let fs = fatfs::FileSystem::new(std::io::Cursor::new(part), fatfs::FsOptions::new())
        .map_err(|e| format!("not FAT: {e}"))?;
    f(&fs)
}

fn read_image(image: &Path) -> Result<Vec<u8>, String> {
    std::fs::read(image).map_err(|e| format!("{}: {e}", image.display()))
}

/// The files in the card's root directory: (name, contents as far as the
/// directory entry's size says, as a reader on a PC sees them).
///
/// # Errors
/// The image has no FAT volume where the MBR says.
pub fn root_files(image: &Path) -> Result<Vec<(String, Vec<u8>)>, String> {
    // A copy: mounting must not touch the evidence.
    with_volume(&mut read_image(image)?, |fs| {
        let mut files = Vec::new();
        for entry in fs.root_dir().iter() {
            let entry = entry.map_err(|e| format!("directory: {e}"))?;
            if entry.is_file() {
                let mut data = Vec::new();
                entry
                    .to_file()
                    .read_to_end(&mut data)
                    .map_err(|e| format!("{}: {e}", entry.file_name()))?;
                files.push((entry.file_name(), data));
            }
        }
        Ok(files)
    })
}

/// Byte offset of the first partition (0 for mkfs.fat's "fake" MBR, whose
/// partition starts at the boot sector itself).
fn partition_start(bytes: &[u8]) -> Option<usize> {
    let entry = bytes.get(446..462)?;
    let lba = u32::from_le_bytes(entry[8..12].try_into().ok()?);
    Some(lba as usize * 512)
}

/// Puts a file `name` holding `data` in the card's root directory (a
/// `CONFIG.TXT`, as a person would copy it on).
///
/// # Errors
/// The image is not a FAT volume or the file cannot be written.
pub fn put_file(image: &Path, name: &str, data: &[u8]) -> Result<(), String> {
    use std::io::Write;
    let mut bytes = read_image(image)?;
    with_volume(&mut bytes, |fs| {
        let mut file = fs
            .root_dir()
            .create_file(name)
            .map_err(|e| format!("{name}: {e}"))?;
        file.write_all(data)
            .and_then(|()| file.flush())
            .map_err(|e| format!("{name}: {e}"))
    })?;
    std::fs::write(image, bytes).map_err(|e| format!("{}: {e}", image.display()))
}

/// Fills the card so that only about `free_bytes` stay free (the card-full
/// scenario).
///
/// # Errors
/// The image is not a FAT volume.
pub fn fill(image: &Path, free_bytes: u64) -> Result<(), String> {
    use std::io::Write;
    let mut bytes = read_image(image)?;
    with_volume(&mut bytes, |fs| {
        let stats = fs.stats().map_err(|e| e.to_string())?;
        let free = u64::from(stats.free_clusters()) * u64::from(stats.cluster_size());
        let mut file = fs
            .root_dir()
            .create_file("FILLER.BIN")
            .map_err(|e| e.to_string())?;
        let chunk = vec![0x5Au8; 1 << 16];
        let mut left = free.saturating_sub(free_bytes);
        while left > 0 {
            let n = left.min(chunk.len() as u64) as usize;
            file.write_all(&chunk[..n]).map_err(|e| e.to_string())?;
            left -= n as u64;
        }
        file.flush().map_err(|e| e.to_string())
    })?;
    std::fs::write(image, bytes).map_err(|e| format!("{}: {e}", image.display()))
}
