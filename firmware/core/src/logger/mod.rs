//! The SD-card logger: a state machine that keeps one log file per power-on
//! on a FAT32 card, over embedded-sdmmc's [`BlockDevice`].
//!
//! ```text
//!            open ok                     write/flush error
//!  NoCard ────────────> Logging ────────────────────────> NoCard
//!    ^  │ (retry every           (count lost frames,        (retry every
//!    └──┘  retry_period_ms)       remember the fault)        retry_period_ms)
//! ```
//!
//! - **One file per power-on**: `RUNnnnnn.WBL`, the next free number in the
//!   root directory, created fresh; the header records
//!   ([`crate::format::header::header_records`]) go first.
//! - **Whole blocks**: block `seq` of the [`BlockEncoder`] is written at file
//!   offset `seq * 512`, so embedded-sdmmc never does a read-modify-write.
//! - **Bounded power-loss window**: every `flush_period_ms` the open block is
//!   written as a snapshot at its own offset. The file is never closed and
//!   reopened per write; it is closed once, by [`CardLogger::close`].
//! - **Written ahead, its entry seldom rewritten**: between flushes the
//!   logger writes blocks of zeros ahead of its data, up to
//!   [`AHEAD_BLOCKS`] (the decoder counts them as unwritten space), and
//!   writes its data blocks into them straight to the card blocks
//!   embedded-sdmmc gave them. The directory entry (whose sector holds up
//!   to 15 earlier rides' entries) and FAT32's FSInfo sector are rewritten
//!   only when the data comes within [`ENTRY_MARGIN_BLOCKS`] of the size
//!   the entry states: about once per [`AHEAD_BLOCKS`] blocks of data
//!   instead of at every flush, and the FAT chain is extended ahead of the
//!   data too. A block written into the space ahead is on the card, inside
//!   the file, the moment it is written.
//!   (embedded-sdmmc 0.10 walks a file's cluster chain from its start for
//!   every seek backwards, so the data cannot go through it once the zeros
//!   are ahead; it tells the card block of each block through
//!   [`CountingDevice::last_write`].)
//! - **Card missing, removed or full**: logging goes on without the card.
//!   Frames that never reached it are counted, and when a card is back the new
//!   file carries a fault record ([`crate::format::FaultSource::Card`], codes
//!   below) and a dropout record ([`DropoutReason::CardUnavailable`]) with the
//!   exact number of frames not written. A full card cannot hold the record
//!   of its own fullness; the count stays in [`LoggerStats`] for the status
//!   output and goes into the next file if space returns.
//!
//! Everything is blocking (embedded-sdmmc is): the writer runs in thread mode
//! while the sampler preempts it from a higher-priority executor.

pub mod layout;
#[cfg(feature = "mock")]
pub mod mock;
pub mod ops;

use core::ops::ControlFlow;

use embedded_sdmmc::{
    BlockDevice, BlockIdx, Error as FsError, Mode, RawDirectory, RawFile, RawVolume, ShortFileName,
    TimeSource, VolumeIdx, VolumeManager,
};

use self::layout::FatLayout;
pub use self::ops::{CardOps, CountingDevice};
use crate::format::header::header_records;
use crate::format::{
    Block, BlockEncoder, Dropout, DropoutReason, Fault, FaultSource, LogInfo, Record, BLOCK_LEN,
};

/// Card fault 1: no card: none inserted, or one that does not answer (seen
/// when opening the card at boot or on a retry). The record's count is the
/// number of failed attempts.
pub const FAULT_CARD_ABSENT: u8 = 1;
/// Card fault 2: a write or flush failed while logging (card removed or
/// broken). Frames not yet on the card at that moment are counted as lost.
pub const FAULT_CARD_WRITE: u8 = 2;
/// Card fault 3: the card is full.
pub const FAULT_CARD_FULL: u8 = 3;
/// Card fault 4: the card answers, but its first partition holds no FAT16
/// or FAT32 volume the logger can write: exFAT (every SDXC card, 64 GB and
/// up, ships so), a GPT or unpartitioned card, a damaged boot sector. It
/// must be formatted FAT32 (`firmware/docs/board.md`). Counted per
/// attempt, as [`FAULT_CARD_ABSENT`].
pub const FAULT_CARD_FORMAT: u8 = 4;
/// Number of card fault codes (`1..=FAULT_CARD_CODES`).
pub const FAULT_CARD_CODES: usize = 4;

/// Retry periods between attempts on a full card (10 s at the default
/// period): a rider who swaps it is logging again soon, and a card left
/// full is not walked for free clusters every second.
pub const FULL_RETRY_PERIODS: u64 = 10;

/// Highest run number a short file name `RUNnnnnn.WBL` can hold.
pub const MAX_RUN: u32 = 99_999;

/// Blocks of zeros the logger keeps written ahead of its data (128 KiB,
/// some 40 s of a ride): the file's size in its directory entry covers
/// them, so the entry is rewritten about once per this many blocks.
pub const AHEAD_BLOCKS: u32 = 256;

/// The directory entry is rewritten (to cover the zeros ahead) once the
/// data comes within this many blocks of the size it states: more than a
/// flush period's blocks at the highest record rate.
pub const ENTRY_MARGIN_BLOCKS: u32 = 16;

/// Timing of the logger.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoggerConfig {
    /// Longest time data stays in RAM before it is on the card with a file
    /// size that covers it: the power-loss window.
    pub flush_period_ms: u32,
    /// Time between two attempts to open a card after a failure.
    pub retry_period_ms: u32,
}

impl LoggerConfig {
    /// Flush twice a second (half a second of data at risk at a power cut,
    /// three extra block writes per flush); retry a missing card every second.
    pub const DEFAULT: Self = Self {
        flush_period_ms: 500,
        retry_period_ms: 1000,
    };
}

impl Default for LoggerConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What goes into the header of every file besides the channel definitions.
#[derive(Clone, Copy, Debug)]
pub struct HeaderSpec<'a> {
    /// Firmware version string.
    pub firmware: &'a str,
    /// Unique device id (the MCU's UID).
    pub device_id: [u8; 12],
    /// Nominal frame rate.
    pub sample_rate_hz: u16,
    /// The `key=value` configuration lines in force.
    pub config: &'a [&'a str],
}

/// A clock for the files' time stamps that always says the same time:
/// before a GPS fix the logger knows no date, and the card log carries the
/// real UTC in its own records.
#[derive(Clone, Copy, Debug)]
pub struct FixedTime(pub embedded_sdmmc::Timestamp);

impl FixedTime {
    /// 2020-01-01 00:00:00, the time stamp of files written before any fix.
    pub const EPOCH: Self = Self(embedded_sdmmc::Timestamp {
        year_since_1970: 50,
        zero_indexed_month: 0,
        zero_indexed_day: 0,
        hours: 0,
        minutes: 0,
        seconds: 0,
    });
}

impl TimeSource for FixedTime {
    fn get_timestamp(&self) -> embedded_sdmmc::Timestamp {
        self.0
    }
}

/// The files' time stamps from the GPS's UTC once it is known
/// ([`crate::channels::SharedStatus::set_utc`]), [`FixedTime::EPOCH`]
/// before. embedded-sdmmc 0.10 asks for the time when it creates a file
/// (creation and modification time) and at every write (modification time,
/// kept in the open file's directory entry in RAM): the entry reaches the
/// card with the flush that writes it anyway, so the time costs no write of
/// its own.
#[derive(Clone, Copy)]
pub struct GpsTime<'a> {
    shared: &'a crate::channels::SharedStatus,
    now_us: fn() -> u64,
}

impl<'a> GpsTime<'a> {
    /// Time stamps from the UTC that `shared` holds, at `now_us` (µs since
    /// boot).
    pub const fn new(shared: &'a crate::channels::SharedStatus, now_us: fn() -> u64) -> Self {
        Self { shared, now_us }
    }
}

/// The FAT time stamp of `unix_s` (UTC), `None` outside FAT's 1980-2107
/// (and embedded-sdmmc's 1970-2097).
#[must_use]
pub fn fat_timestamp(unix_s: u64) -> Option<embedded_sdmmc::Timestamp> {
    const DAYS_1970_TO_2000: u64 = 10_957;
    let days = unix_s / 86_400;
    let secs = unix_s % 86_400;
    let days_since_2000 = u16::try_from(days.checked_sub(DAYS_1970_TO_2000)?).ok()?;
    let (year, month, day) = crate::format::UtcTime {
        days_since_2000,
        ms_of_day: 0,
    }
    .date();
    if year < 1980 {
        return None;
    }
    embedded_sdmmc::Timestamp::from_calendar(
        u16::try_from(year).ok()?,
        month as u8,
        day as u8,
        (secs / 3600) as u8,
        (secs / 60 % 60) as u8,
        (secs % 60) as u8,
    )
    .ok()
}

impl TimeSource for GpsTime<'_> {
    fn get_timestamp(&self) -> embedded_sdmmc::Timestamp {
        self.shared
            .unix_s((self.now_us)())
            .and_then(fat_timestamp)
            .unwrap_or(FixedTime::EPOCH.0)
    }
}

/// Where the logger stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LoggerState {
    /// No file open: waiting for the next attempt to open a card.
    NoCard,
    /// No file open: the card answers but holds no FAT16 or FAT32 volume
    /// ([`FAULT_CARD_FORMAT`]); tried again like a missing card.
    UnusableCard,
    /// No file open: the card is full ([`FAULT_CARD_FULL`]); tried again
    /// every [`FULL_RETRY_PERIODS`] retry periods.
    CardFull,
    /// Writing `RUNnnnnn.WBL` with this run number.
    Logging {
        /// The run number of the open file.
        run: u32,
    },
}

/// Counters since boot, for the status output and the tests.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoggerStats {
    /// Files created.
    pub files_opened: u32,
    /// Sealed blocks written.
    pub blocks_written: u32,
    /// Successful flushes (snapshot, and the directory entry when due).
    pub flushes: u32,
    /// Rewrites of the open file's directory entry (and FSInfo) while
    /// logging, closing included.
    pub entry_writes: u32,
    /// Blocks of zeros written ahead of the data.
    pub ahead_writes: u32,
    /// Frames a reader finds in the current file: in blocks that the file
    /// size of the last flush covers, in their latest written version.
    /// Frames past it are lost if the card goes now.
    pub frames_on_card: u32,
    /// Frames that never reached a card, since boot.
    pub frames_lost: u32,
    /// Frames lost and not yet reported in a dropout record on a card.
    pub frames_lost_unreported: u32,
    /// Faults by code (`faults[code - 1]`), since boot.
    pub faults: [u32; FAULT_CARD_CODES],
    /// Records the encoder refused (a bug or an oversized config line).
    pub encode_errors: u32,
}

/// Why [`CardLogger::close`] could not close the file cleanly.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum CloseError {
    /// No file was open.
    NoFile,
    /// The final write, flush or close failed; the file keeps the state of
    /// its last successful flush.
    Card,
}

/// The card's file system with room for one volume, directory and file
/// open at a time: all the logger needs, over a device that counts its
/// operations ([`ops`]). The board reads `CONFIG.TXT` and runs the
/// self-test through the same type, so the firmware holds one copy of
/// embedded-sdmmc's code, not one per set of limits or device.
pub type Volumes<D, T> = VolumeManager<CountingDevice<D>, T, 1, 1, 1>;

/// The file system over `device`, its operations counted from zero.
pub fn volumes<D: BlockDevice, T: TimeSource>(device: D, time: T) -> Volumes<D, T> {
    VolumeManager::new_with_limits(CountingDevice::new(device), time, 0)
}

/// The logger (see the module docs).
pub struct CardLogger<'a, D: BlockDevice, T: TimeSource> {
    fs: Volumes<D, T>,
    header: HeaderSpec<'a>,
    config: LoggerConfig,
    encoder: BlockEncoder,
    open: Option<OpenFile>,
    next_try_us: u64,
    next_flush_us: u64,
    /// Where the open file's blocks are.
    blocks: FileBlocks,
    /// When the last flush was made.
    flushed_at_us: Option<u64>,
    /// Frames in the blocks written so far, whether or not the file size
    /// covers them yet.
    frames_written: u32,
    /// Fault counts not yet on a card, by code.
    faults_unreported: [u16; FAULT_CARD_CODES],
    stats: LoggerStats,
    /// The last card fault counted (0: none since the file opened): what
    /// [`Self::state`] shows while no file is open.
    last_fault: u8,
}

#[derive(Clone, Copy, Debug)]
struct OpenFile {
    volume: RawVolume,
    dir: RawDirectory,
    file: RawFile,
    run: u32,
}

/// Why the card's volume could not be opened: a card that answered with
/// something other than a FAT16 or FAT32 volume, or none that answered.
fn open_fault<E: core::fmt::Debug + core::error::Error>(err: &FsError<E>) -> u8 {
    match err {
        FsError::FormatError(_) => FAULT_CARD_FORMAT,
        _ => FAULT_CARD_ABSENT,
    }
}

/// What made a card operation fail, reduced to the fault it stands for.
fn fault_code<E: core::fmt::Debug + core::error::Error>(err: &FsError<E>) -> u8 {
    match err {
        FsError::DiskFull | FsError::NotEnoughSpace => FAULT_CARD_FULL,
        _ => FAULT_CARD_WRITE,
    }
}

impl<'a, D: BlockDevice, T: TimeSource> CardLogger<'a, D, T> {
    /// A logger that will open the card at the first [`Self::poll`].
    pub fn new(device: D, time: T, header: HeaderSpec<'a>, config: LoggerConfig) -> Self {
        Self {
            fs: volumes(device, time),
            header,
            config,
            encoder: BlockEncoder::new(),
            open: None,
            next_try_us: 0,
            next_flush_us: 0,
            blocks: FileBlocks::NONE,
            flushed_at_us: None,
            frames_written: 0,
            faults_unreported: [0; FAULT_CARD_CODES],
            stats: LoggerStats::default(),
            last_fault: 0,
        }
    }

    /// Where the logger stands.
    pub fn state(&self) -> LoggerState {
        match self.open {
            Some(f) => LoggerState::Logging { run: f.run },
            None => match self.last_fault {
                FAULT_CARD_FORMAT => LoggerState::UnusableCard,
                FAULT_CARD_FULL => LoggerState::CardFull,
                _ => LoggerState::NoCard,
            },
        }
    }

    /// Counters since boot.
    pub fn stats(&self) -> LoggerStats {
        self.stats
    }

    /// Runs `f` on the block device (the tests' fault injection uses this).
    pub fn with_device<R>(&self, f: impl FnOnce(&mut D) -> R) -> R {
        self.fs.device(|d| f(d.inner_mut()))
    }

    /// The block device back, for a new file system on the same card once
    /// the log is closed (the on-target smoke test reads its log this way).
    pub fn into_device(self) -> D {
        self.fs.free().0.into_inner()
    }

    /// Card operations since boot (every read, write and size query,
    /// whether it succeeded or not): the writer counts them per iteration
    /// (`app::writer`).
    pub fn card_ops(&self) -> CardOps {
        self.fs.device(|d| d.ops())
    }

    /// Logs one record at local time `now_us`. Without a card, frames are
    /// counted as lost, and so are the frames a dropout record (the queue's)
    /// reports; other records are dropped.
    pub fn push(&mut self, rec: &Record<'_>, now_us: u64) {
        if self.open.is_none() {
            match rec {
                Record::Frame(_) => self.count_lost(1),
                Record::Dropout(d) => self.count_lost(d.frames_lost),
                _ => {}
            }
            return;
        }
        self.encode(rec, now_us);
    }

    /// Does what is due at `now_us`: a flush while logging, an attempt to
    /// open the card without one. Call it at least every few tens of ms.
    pub fn poll(&mut self, now_us: u64) {
        match self.open {
            Some(_) if now_us >= self.next_flush_us => self.flush(now_us),
            Some(_) => {}
            None if now_us >= self.next_try_us => self.try_open(now_us),
            None => {}
        }
    }

    /// Writes everything, flushes and closes the file (end of ride, clean
    /// shutdown): after this the file system is clean.
    ///
    /// # Errors
    /// No file was open, or the card failed (the file keeps its last flush).
    pub fn close(&mut self, now_us: u64) -> Result<(), CloseError> {
        if self.open.is_none() {
            return Err(CloseError::NoFile);
        }
        self.flush(now_us);
        let f = self.open.take().ok_or(CloseError::Card)?;
        // Closing rewrites the entry once more (its size and time).
        let closed = self.fs.close_file(f.file);
        self.release(f.dir, f.volume);
        closed.map_err(|_| CloseError::Card)?;
        self.stats.entry_writes = self.stats.entry_writes.saturating_add(1);
        Ok(())
    }

    fn count_lost(&mut self, frames: u32) {
        self.stats.frames_lost = self.stats.frames_lost.saturating_add(frames);
        self.stats.frames_lost_unreported =
            self.stats.frames_lost_unreported.saturating_add(frames);
    }

    fn count_fault(&mut self, code: u8) {
        let i = usize::from(code - 1);
        self.stats.faults[i] = self.stats.faults[i].saturating_add(1);
        self.faults_unreported[i] = self.faults_unreported[i].saturating_add(1);
        self.last_fault = code;
    }

    /// When to try the card again after the fault just counted: a full
    /// card waits [`FULL_RETRY_PERIODS`] periods (each attempt on it walks
    /// the FAT for free clusters), any other one period.
    fn retry_at(&self, now_us: u64) -> u64 {
        let periods = if self.last_fault == FAULT_CARD_FULL {
            FULL_RETRY_PERIODS
        } else {
            1
        };
        now_us.saturating_add(u64::from(self.config.retry_period_ms) * 1000 * periods)
    }

    /// Encodes `rec` and writes the block it closed, if any.
    fn encode(&mut self, rec: &Record<'_>, now_us: u64) {
        let Some(f) = self.open else { return };
        let frames_before = self.encoder.frames_total();
        // A block that closes is the one open now.
        let seq = self.encoder.open_seq();
        let written = match self.encoder.push(rec) {
            Ok(Some(block)) => Some(self.blocks.write(&self.fs, f.file, seq, block)),
            Ok(None) => None,
            Err(_) => {
                self.stats.encode_errors = self.stats.encode_errors.saturating_add(1);
                None
            }
        };
        match written {
            Some(Ok(())) => {
                self.stats.blocks_written = self.stats.blocks_written.saturating_add(1);
                // The closed block holds every frame before `rec`; it only
                // counts once a flush has put its offset inside the file
                // size (the snapshot block being overwritten already is).
                if seq < self.blocks.size {
                    self.stats.frames_on_card = frames_before;
                }
                self.frames_written = frames_before;
            }
            Some(Err(e)) => self.fail(fault_code(&e), now_us),
            None => {}
        }
    }

    /// Snapshot of the open block plus a file flush.
    fn flush(&mut self, now_us: u64) {
        let Some(f) = self.open else { return };
        self.flushed_at_us = Some(now_us);
        self.next_flush_us = now_us.saturating_add(u64::from(self.config.flush_period_ms) * 1000);
        let seq = self.encoder.open_seq();
        let (snapshot, data_blocks) = match self.encoder.snapshot() {
            Some(block) => (
                self.blocks.write(&self.fs, f.file, seq, block),
                seq.saturating_add(1),
            ),
            None => (Ok(()), seq),
        };
        let entry = snapshot.and_then(|()| self.update_entry(f.file, data_blocks));
        match entry {
            Ok(()) => {
                self.stats.flushes = self.stats.flushes.saturating_add(1);
                self.stats.frames_on_card = self.encoder.frames_total();
                self.frames_written = self.encoder.frames_total();
                // Whatever was pending is now in this file, on the card.
                self.faults_unreported = [0; FAULT_CARD_CODES];
                self.stats.frames_lost_unreported = 0;
            }
            Err(e) => self.fail(fault_code(&e), now_us),
        }
    }

    /// The card failed: count what did not reach it, let go of the file.
    fn fail(&mut self, code: u8, now_us: u64) {
        self.count_fault(code);
        let mut visible = self.stats.frames_on_card;
        if let Some(f) = self.open.take() {
            // A card that still answers (a full one) takes the final size
            // of the file, which then shows every block written so far.
            // The handles are released even when the card does not answer.
            if self.fs.close_file(f.file).is_ok() {
                visible = self.frames_written;
            }
            self.release(f.dir, f.volume);
        }
        self.count_lost(self.encoder.frames_total().wrapping_sub(visible));
        self.frames_written = 0;
        self.encoder = BlockEncoder::new();
        self.stats.frames_on_card = 0;
        self.blocks = FileBlocks::NONE;
        self.next_try_us = self.retry_at(now_us);
    }

    /// Writes one block of zeros ahead of the data, if fewer than
    /// [`AHEAD_BLOCKS`] are and no flush was made at `now_us`: the writer
    /// calls it when it has no record waiting (`app::writer`), so the zeros
    /// never hold up a backlog. A full card stops the zeros, not the
    /// logging: the data takes what space is left.
    pub fn write_ahead(&mut self, now_us: u64) {
        let Some(f) = self.open else { return };
        let open_seq = self.encoder.open_seq();
        let b = &mut self.blocks;
        let full = b.held >= open_seq.saturating_add(AHEAD_BLOCKS);
        if b.ahead_stopped || full || self.flushed_at_us == Some(now_us) {
            return;
        }
        match b.write(&self.fs, f.file, b.held, &[0; BLOCK_LEN]) {
            Ok(()) => self.stats.ahead_writes = self.stats.ahead_writes.saturating_add(1),
            Err(FsError::DiskFull | FsError::NotEnoughSpace) => b.ahead_stopped = true,
            Err(e) => self.fail(fault_code(&e), now_us),
        }
    }

    /// Rewrites the directory entry (and FSInfo) when [`entry_due`]: its
    /// size then covers every block the file holds.
    fn update_entry(&mut self, file: RawFile, data_blocks: u32) -> Result<(), FsError<D::Error>> {
        let b = &mut self.blocks;
        if entry_due(data_blocks, b.size, b.held) {
            self.fs.flush_file(file)?;
            self.stats.entry_writes = self.stats.entry_writes.saturating_add(1);
            b.size = b.held;
        }
        Ok(())
    }

    fn release(&mut self, dir: RawDirectory, volume: RawVolume) {
        // Closing handles only fails for unknown handles, which these are not.
        let _ = self.fs.close_dir(dir);
        let _ = self.fs.close_volume(volume);
    }

    /// Opens the card, creates the next run's file and writes its header,
    /// then the fault and dropout records of what happened without a card.
    fn try_open(&mut self, now_us: u64) {
        let volume = match self.fs.open_raw_volume(VolumeIdx(0)) {
            Ok(volume) => volume,
            Err(e) => {
                self.count_fault(open_fault(&e));
                self.next_try_us = self.retry_at(now_us);
                return;
            }
        };
        let opened = self
            .fs
            .open_root_dir(volume)
            .map_err(|e| (e, None))
            .and_then(|dir| {
                let run = next_run(&self.fs, dir).map_err(|e| (e, Some(dir)))?;
                let name = run_file_name(run).map_err(|e| (e, Some(dir)))?;
                let file = self
                    .fs
                    .open_file_in_dir(dir, name, Mode::ReadWriteCreate)
                    .map_err(|e| (e, Some(dir)))?;
                Ok(OpenFile {
                    volume,
                    dir,
                    file,
                    run,
                })
            });
        let f = match opened {
            Ok(f) => f,
            Err((e, dir)) => {
                if let Some(dir) = dir {
                    let _ = self.fs.close_dir(dir);
                }
                let _ = self.fs.close_volume(volume);
                let code = match e {
                    FsError::DiskFull | FsError::NotEnoughSpace => FAULT_CARD_FULL,
                    _ => FAULT_CARD_ABSENT,
                };
                self.count_fault(code);
                self.next_try_us = self.retry_at(now_us);
                return;
            }
        };
        self.open = Some(f);
        self.last_fault = 0;
        self.stats.files_opened = self.stats.files_opened.saturating_add(1);
        self.encoder = BlockEncoder::new();
        self.stats.frames_on_card = 0;
        self.blocks = FileBlocks::NONE;
        // Blocks embedded-sdmmc gives the file past the data region are
        // not written into directly (the zeros stop there).
        self.blocks.data_end = self
            .fs
            .device(|d| FatLayout::of(&*d).map_or(0, |l| l.data_end()));
        let info = LogInfo {
            t_us: now_us,
            firmware: self.header.firmware,
            device_id: self.header.device_id,
            sample_rate_hz: self.header.sample_rate_hz,
            run: f.run,
        };
        let config = self.header.config;
        for rec in header_records(info, config.iter().copied()) {
            self.encode(&rec, now_us);
        }
        self.report_unavailable(now_us);
        self.flush(now_us);
        if self.open.is_none() {
            // The card failed before the file held a frame (full, or pulled
            // out): do not leave an empty file behind on every retry.
            self.delete_run(f.run);
        }
    }

    /// Best effort: removes the (closed) file of `run`.
    fn delete_run(&mut self, run: u32) {
        let Ok(name) = run_file_name::<D::Error>(run) else {
            return;
        };
        let Ok(volume) = self.fs.open_raw_volume(VolumeIdx(0)) else {
            return;
        };
        if let Ok(dir) = self.fs.open_root_dir(volume) {
            let _ = self.fs.delete_entry_in_dir(dir, name);
            let _ = self.fs.close_dir(dir);
        }
        let _ = self.fs.close_volume(volume);
    }

    fn report_unavailable(&mut self, now_us: u64) {
        let pending = self.faults_unreported;
        for (i, &count) in pending.iter().enumerate() {
            if count > 0 {
                let rec = Record::Fault(Fault {
                    t_us: now_us,
                    source: FaultSource::Card,
                    // `i < FAULT_CARD_CODES`, a small number.
                    code: (i + 1) as u8,
                    count,
                });
                self.encode(&rec, now_us);
            }
        }
        let lost = self.stats.frames_lost_unreported;
        if lost > 0 {
            let rec = Record::Dropout(Dropout {
                t_us: now_us,
                frames_lost: lost,
                reason: DropoutReason::CardUnavailable,
            });
            self.encode(&rec, now_us);
        }
    }
}

/// Whether the directory entry is due for a rewrite: the data, `data`
/// blocks long, has fewer than [`ENTRY_MARGIN_BLOCKS`] to spare in the
/// `size` the entry states, and the file holds more (`held`, never less
/// than `data`) than that size. Without zeros ahead (`held == data`) that
/// is every flush that has new data, as it was before them.
fn entry_due(data: u32, size: u32, held: u32) -> bool {
    data.saturating_add(ENTRY_MARGIN_BLOCKS) > size && held > size
}

/// Where the open file's blocks are (see the module docs).
struct FileBlocks {
    /// Blocks the directory entry's file size covers (as of its last
    /// rewrite).
    size: u32,
    /// Blocks the file holds: data, then zeros written ahead.
    held: u32,
    /// The card block of file block `seq` at `[seq % AHEAD_BLOCKS]`, for
    /// the open block and those ahead of it (0: not known; block 0 is the
    /// card's MBR, never a file's).
    card: [u32; AHEAD_BLOCKS as usize],
    /// The card refused to grow the file ahead (full), or gave it a block
    /// past the data region: no more zeros.
    ahead_stopped: bool,
    /// The block after the volume's data region (0: not known, no zeros).
    data_end: u32,
}

impl FileBlocks {
    /// No file.
    const NONE: Self = Self {
        size: 0,
        held: 0,
        card: [0; AHEAD_BLOCKS as usize],
        ahead_stopped: false,
        data_end: 0,
    };

    /// Writes `block` as block `seq` of `file`: straight to its card block
    /// when it lies in the zeros written ahead, else through embedded-sdmmc
    /// at the end of the file (which grows), learning its card block.
    fn write<D: BlockDevice, T: TimeSource>(
        &mut self,
        fs: &Volumes<D, T>,
        file: RawFile,
        seq: u32,
        block: &Block,
    ) -> Result<(), FsError<D::Error>> {
        let slot = (seq % AHEAD_BLOCKS) as usize;
        if seq < self.held && self.card[slot] != 0 {
            let at = BlockIdx(self.card[slot]);
            let contents = embedded_sdmmc::Block { contents: *block };
            return fs
                .device(|d| d.write(core::slice::from_ref(&contents), at))
                .map_err(FsError::DeviceError);
        }
        // Past the end (or a block whose card block is not known:
        // embedded-sdmmc then seeks back through the chain).
        write_block(fs, file, seq, block)?;
        // The file's block is the last card write of embedded-sdmmc's
        // write, after any FAT update; its first bytes tell it is.
        self.card[slot] = match fs.device(|d| d.last_write()) {
            Some((at, head)) if block.starts_with(&head) && at.0 != 0 => at.0,
            _ => 0,
        };
        if self.card[slot] >= self.data_end {
            // Past the data region (a full volume): written through
            // embedded-sdmmc from now on, as it places it.
            self.card[slot] = 0;
            self.ahead_stopped = true;
        }
        self.held = self.held.max(seq.saturating_add(1));
        Ok(())
    }
}

/// Writes one whole block at its offset in the file.
fn write_block<D: BlockDevice, T: TimeSource>(
    fs: &Volumes<D, T>,
    file: RawFile,
    seq: u32,
    block: &Block,
) -> Result<(), FsError<D::Error>> {
    let offset = seq
        .checked_mul(BLOCK_LEN as u32)
        .ok_or(FsError::NotEnoughSpace)?;
    fs.file_seek_from_start(file, offset)?;
    fs.write(file, block)
}

/// The run number after the highest `RUNnnnnn.WBL` in `dir` (1 on an empty
/// card).
fn next_run<D: BlockDevice, T: TimeSource>(
    fs: &Volumes<D, T>,
    dir: RawDirectory,
) -> Result<u32, FsError<D::Error>> {
    let mut highest = 0;
    fs.iterate_dir(dir, |entry| {
        if let Some(run) = parse_run(&entry.name) {
            highest = highest.max(run);
        }
        ControlFlow::Continue(())
    })?;
    if highest >= MAX_RUN {
        return Err(FsError::NotEnoughSpace);
    }
    Ok(highest + 1)
}

/// `RUN00042.WBL` -> 42; `None` for any other name. Public for readers of
/// a card (the on-target power-cut check walks every run file).
#[must_use]
pub fn parse_run(name: &ShortFileName) -> Option<u32> {
    let digits = name.base_name().strip_prefix(b"RUN")?;
    if name.extension() != b"WBL" || digits.len() != 5 {
        return None;
    }
    digits.iter().try_fold(0u32, |acc, &d| {
        d.is_ascii_digit().then(|| acc * 10 + u32::from(d - b'0'))
    })
}

/// 42 -> `RUN00042.WBL`.
fn run_file_name<E: core::fmt::Debug + core::error::Error>(
    run: u32,
) -> Result<ShortFileName, FsError<E>> {
    let mut text = *b"RUN00000.WBL";
    let mut n = run;
    for d in text[3..8].iter_mut().rev() {
        *d = b'0' + (n % 10) as u8;
        n /= 10;
    }
    let text = core::str::from_utf8(&text).map_err(|_| FsError::NotFound)?;
    ShortFileName::create_from_str(text).map_err(FsError::FilenameError)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_entry_is_due_within_its_margin_when_the_file_holds_more() {
        // A new file: nothing stated yet, a header block held.
        assert!(entry_due(0, 0, 1));
        // 16 blocks to spare: not yet; 15: due.
        assert!(!entry_due(100, 116, 300));
        assert!(entry_due(101, 116, 300));
        // Nothing held beyond the stated size: a rewrite would change nothing.
        assert!(!entry_due(110, 116, 116));
        // Without zeros ahead: due whenever there is new data.
        assert!(entry_due(117, 116, 117));
        assert!(!entry_due(116, 116, 116));
    }

    #[test]
    fn run_names_round_trip() {
        for run in [1, 42, 99_999] {
            let name = run_file_name::<std::io::Error>(run).expect("valid name");
            assert_eq!(parse_run(&name), Some(run));
        }
        let other = ShortFileName::create_from_str("RUN0001X.WBL").expect("valid name");
        assert_eq!(parse_run(&other), None);
        let other = ShortFileName::create_from_str("RUN00001.CSV").expect("valid name");
        assert_eq!(parse_run(&other), None);
    }
}
