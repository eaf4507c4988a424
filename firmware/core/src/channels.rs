//! The queues and shared state between the tasks, each with its size and who
//! fills and drains it.
//!
//! | item | producer | consumer |
//! |---|---|---|
//! | [`RecordQueue`] | sampler (high-priority executor), GPS task | writer (thread mode) |
//! | [`SharedStatus`] | GPS task, writer | sampler (status bits, LED) |
//!
//! Queue sizing. The producers make at most [`MAX_RECORDS_PER_S`] = 125
//! records a second: 100 frames, a 20 Hz GPS, and now and then a UTC pair,
//! an alert, a kick, a marker or a fault. The writer drains the queue once
//! per iteration (`app::writer`): a poll (a flush every 500 ms: the open
//! block's snapshot, and the directory entry and FSInfo when the data nears
//! the size the entry states; between flushes one block of zeros written
//! ahead of the data, `logger`) and one record's push (which writes a
//! block when it closes one; at the end of the file, a cluster boundary
//! reads and writes both FATs). Counted with a counting device
//! (`logger::ops`) over ten minutes of ride on FAT cards with 512-byte to
//! 4 KiB clusters (`tests/writer_ops.rs`), before the logger wrote zeros
//! ahead of its data, one iteration while logging made at most
//! [`WRITER_OPS_PER_ITERATION`] = 14 card operations, and the slowest by
//! the SD specification was [`WORST_ITERATION_OPS`]: 8 writes and 5 reads.
//! Writing ahead, iterations make at most 10 (6 writes, 3 reads) on empty
//! and nearly full cards, 11 in the writer task's own test; the sizing
//! keeps the earlier bound as margin. The specification lets an SDHC/SDXC
//! card stay busy [`CARD_WRITE_STALL_US`] = 500 ms on a write and
//! [`CARD_READ_STALL_US`] = 100 ms on a read: 8 × 0.5 s + 5 × 0.1 s = 4.5 s
//! ([`WORST_ITERATION_US`]), during which the writer drains nothing:
//! 4.5 s × 125 /s = 563 records. [`QUEUE_LEN`] = 576 records hold
//! [`QUEUE_HOLDS_US`] = 4.608 s: the worst iteration, at least
//! [`MIN_QUEUE_US`] = 4 s, and more than one operation at the writer's
//! 1.5 s budget (`drivers::sd_spi::CARD_OPERATION_BUDGET_US`). A longer
//! stall (a fragmented card whose free-cluster search reads many FAT
//! blocks, the search of the whole FAT where the zeros ahead find the card
//! full, a card past the specification) costs frames, counted and logged
//! as a dropout.
//!
//! 576 records of 64 bytes (on the MCU) are 36 KiB: the board keeps the
//! queue in the core-coupled RAM (CCM), which only the CPU reaches; nothing
//! in a record is ever a DMA buffer (`firmware/docs/board.md`, memory plan).

use core::sync::atomic::{AtomicU32, Ordering};

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;

use crate::drivers::sd_spi::CARD_OPERATION_BUDGET_US;
use crate::format::{Dropout, DropoutReason, Record};
use crate::logger::CardOps;

/// Most records the producers make per second (see the module docs).
pub const MAX_RECORDS_PER_S: u64 = 125;
/// Most card operations one writer iteration makes while a file is open
/// (see the module docs).
pub const WRITER_OPS_PER_ITERATION: u32 = 14;
/// Longest the SD specification lets an SDHC/SDXC card stay busy on a
/// write, µs (SDSC cards: 250 ms).
pub const CARD_WRITE_STALL_US: u64 = 500_000;
/// Longest the SD specification lets a card take to answer a read, µs.
pub const CARD_READ_STALL_US: u64 = 100_000;
/// The writer iteration that is slowest by the SD specification's limits
/// (see the module docs).
pub const WORST_ITERATION_OPS: CardOps = CardOps {
    reads: 5,
    writes: 8,
    other: 0,
};
/// The longest writer iteration the queue must bridge, µs.
pub const WORST_ITERATION_US: u64 = iteration_stall_us(WORST_ITERATION_OPS);
/// The queue holds at least this long at the highest record rate, µs.
pub const MIN_QUEUE_US: u64 = 4_000_000;
/// Capacity of the sampler -> writer queue, in records (see the module docs).
pub const QUEUE_LEN: usize = 576;
/// How long [`QUEUE_LEN`] records last at [`MAX_RECORDS_PER_S`], µs.
pub const QUEUE_HOLDS_US: u64 = queue_holds_us(QUEUE_LEN as u64, MAX_RECORDS_PER_S);
// Holds the worst iteration, at least 4 s, and one operation at its budget.
const _: () = assert!(QUEUE_HOLDS_US >= WORST_ITERATION_US);
const _: () = assert!(QUEUE_HOLDS_US >= MIN_QUEUE_US);
const _: () = assert!(QUEUE_HOLDS_US >= CARD_OPERATION_BUDGET_US);

/// The longest the SD specification lets `ops` take, µs: each write at
/// [`CARD_WRITE_STALL_US`], each read and other command at
/// [`CARD_READ_STALL_US`].
#[must_use]
pub const fn iteration_stall_us(ops: CardOps) -> u64 {
    ops.writes as u64 * CARD_WRITE_STALL_US
        + (ops.reads as u64 + ops.other as u64) * CARD_READ_STALL_US
}

/// How long a queue of `records` lasts when `per_s` records come a second,
/// µs (rounded down; `u64::MAX` when nothing comes).
#[must_use]
pub const fn queue_holds_us(records: u64, per_s: u64) -> u64 {
    if per_s == 0 {
        return u64::MAX;
    }
    records * 1_000_000 / per_s
}

/// Records a queue needs to bridge `stall_us` when `per_s` records come a
/// second (rounded up).
#[must_use]
pub const fn records_for(stall_us: u64, per_s: u64) -> u64 {
    (stall_us * per_s).div_ceil(1_000_000)
}

/// The bounded queue from the producers to the SD writer.
///
/// Producers never wait: when the queue is full a frame is counted as
/// dropped, and the next push that finds room for two records first sends a
/// [`Dropout`] ([`DropoutReason::QueueFull`]) with the exact count. Usable
/// from any executor: the lock is a critical section.
pub struct RecordQueue {
    channel: Channel<CriticalSectionRawMutex, Record<'static>, QUEUE_LEN>,
    /// Frames dropped and not yet reported in a dropout record.
    frames_dropped: AtomicU32,
    /// Records other than frames dropped since boot (not reported on the
    /// card: the dropout record counts frames).
    others_dropped: AtomicU32,
    /// Highest fill level seen, records.
    high_water: AtomicU32,
}

impl Default for RecordQueue {
    fn default() -> Self {
        Self::new()
    }
}

impl RecordQueue {
    /// An empty queue (a `static`).
    #[must_use]
    pub const fn new() -> Self {
        Self {
            channel: Channel::new(),
            frames_dropped: AtomicU32::new(0),
            others_dropped: AtomicU32::new(0),
            high_water: AtomicU32::new(0),
        }
    }

    /// Queues `rec`; returns whether it was queued. Never blocks.
    ///
    /// Frames and the dropout record are pushed by one producer, the
    /// sampler; other producers push other records, so the dropped-frame
    /// count has one writer and one reader at a time.
    pub fn push(&self, rec: Record<'static>) -> bool {
        let dropped = self.frames_dropped.load(Ordering::Acquire);
        // The dropout goes in only with room for the record after it, so
        // the reader learns of the loss before the next frame.
        if dropped > 0 && matches!(rec, Record::Frame(_)) && self.channel.free_capacity() >= 2 {
            let dropout = Record::Dropout(Dropout {
                t_us: rec.t_us(),
                frames_lost: dropped,
                reason: DropoutReason::QueueFull,
            });
            if self.channel.try_send(dropout).is_ok() {
                self.frames_dropped.fetch_sub(dropped, Ordering::AcqRel);
            }
        }
        let queued = self.channel.try_send(rec).is_ok();
        if queued {
            let len = u32::try_from(self.channel.len()).unwrap_or(u32::MAX);
            self.high_water.fetch_max(len, Ordering::Relaxed);
        } else if matches!(rec, Record::Frame(_)) {
            self.frames_dropped.fetch_add(1, Ordering::AcqRel);
        } else {
            self.others_dropped.fetch_add(1, Ordering::Relaxed);
        }
        queued
    }

    /// Waits for the next record.
    pub async fn pop(&self) -> Record<'static> {
        self.channel.receive().await
    }

    /// Takes the next record if there is one.
    pub fn try_pop(&self) -> Option<Record<'static>> {
        self.channel.try_receive().ok()
    }

    /// Records waiting.
    pub fn len(&self) -> usize {
        self.channel.len()
    }

    /// Whether no record is waiting.
    pub fn is_empty(&self) -> bool {
        self.channel.is_empty()
    }

    /// Highest fill level seen since boot, records.
    pub fn high_water(&self) -> u32 {
        self.high_water.load(Ordering::Relaxed)
    }

    /// Frames dropped and not yet reported on the queue.
    pub fn frames_dropped_pending(&self) -> u32 {
        self.frames_dropped.load(Ordering::Acquire)
    }

    /// Records other than frames dropped since boot.
    pub fn others_dropped(&self) -> u32 {
        self.others_dropped.load(Ordering::Relaxed)
    }
}

/// The writer's card, as the sampler shows it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum CardHealth {
    /// No file open: no card, or none that answers.
    Absent = 0,
    /// Logging to a file.
    Logging = 1,
    /// A card that answers without a FAT16 or FAT32 volume.
    Unusable = 2,
    /// A full card.
    Full = 3,
}

impl From<crate::logger::LoggerState> for CardHealth {
    fn from(state: crate::logger::LoggerState) -> Self {
        use crate::logger::LoggerState;
        match state {
            LoggerState::NoCard => Self::Absent,
            LoggerState::UnusableCard => Self::Unusable,
            LoggerState::CardFull => Self::Full,
            LoggerState::Logging { .. } => Self::Logging,
        }
    }
}

/// Small facts the tasks share, each a single word (no 64-bit atomics on
/// the Cortex-M4).
pub struct SharedStatus {
    /// Local time of the last GPS fix with a position, ms since boot; 0:
    /// none yet.
    last_fix_ms: AtomicU32,
    /// UTC at boot, s since the Unix epoch (0: not known yet).
    boot_unix_s: AtomicU32,
    /// Where the writer stands ([`CardHealth`] as a number).
    card: AtomicU32,
    /// Whether the writer should close the log (0/1).
    stop: AtomicU32,
    /// Whether the supply is below the power-fail threshold now (0/1), and
    /// how often it fell below it since boot (high bits).
    power: AtomicU32,
    /// Most card operations of one writer iteration with a file open.
    writer_ops_max: AtomicU32,
    /// Most card operations of one writer iteration that opened a card.
    writer_open_ops_max: AtomicU32,
    /// Longest busy time of one writer iteration, µs.
    writer_busy_max_us: AtomicU32,
}

/// The writer's worst iterations since boot ([`SharedStatus::writer`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WriterFigures {
    /// Most card operations of one iteration while logging (what the queue
    /// is sized for: at most [`WRITER_OPS_PER_ITERATION`]).
    pub ops_max: u32,
    /// Most card operations of one iteration that opened a card (or tried
    /// to): the boot's, and each retry's.
    pub open_ops_max: u32,
    /// Longest time one iteration kept the writer busy, µs.
    pub busy_max_us: u32,
}

impl Default for SharedStatus {
    fn default() -> Self {
        Self::new()
    }
}

impl SharedStatus {
    /// Nothing known yet.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            last_fix_ms: AtomicU32::new(0),
            boot_unix_s: AtomicU32::new(0),
            card: AtomicU32::new(0),
            stop: AtomicU32::new(0),
            power: AtomicU32::new(0),
            writer_ops_max: AtomicU32::new(0),
            writer_open_ops_max: AtomicU32::new(0),
            writer_busy_max_us: AtomicU32::new(0),
        }
    }

    /// The GPS task's (local time, UTC) pair: the UTC second at boot is
    /// kept for the files' time stamps ([`crate::logger::GpsTime`]). A pair
    /// before 1970 + 1 s of boot time (impossible) is ignored.
    pub fn set_utc(&self, sync: crate::format::UtcSync) {
        let boot_unix_s = (sync.unix_ms / 1000).saturating_sub(sync.t_us / 1_000_000);
        if let Ok(s) = u32::try_from(boot_unix_s) {
            if s > 0 {
                self.boot_unix_s.store(s, Ordering::Relaxed);
            }
        }
    }

    /// UTC at `now_us` (µs since boot), seconds since the Unix epoch, once
    /// the GPS has given it ([`Self::set_utc`]).
    pub fn unix_s(&self, now_us: u64) -> Option<u64> {
        match self.boot_unix_s.load(Ordering::Relaxed) {
            0 => None,
            s => Some(u64::from(s) + now_us / 1_000_000),
        }
    }

    /// The GPS task saw a fix with a position at `t_us`.
    pub fn set_fix(&self, t_us: u64) {
        let ms = u32::try_from(t_us / 1000).unwrap_or(u32::MAX).max(1);
        self.last_fix_ms.store(ms, Ordering::Relaxed);
    }

    /// Local time of the last fix with a position, µs since boot (to the
    /// millisecond); `None` before the first. Frame assembly decides from it
    /// whether the GPS is stale.
    pub fn last_fix_us(&self) -> Option<u64> {
        match self.last_fix_ms.load(Ordering::Relaxed) {
            0 => None,
            ms => Some(u64::from(ms) * 1000),
        }
    }

    /// The writer reports where it stands.
    pub fn set_card(&self, health: CardHealth) {
        self.card.store(health as u32, Ordering::Relaxed);
    }

    /// Where the writer stands.
    pub fn card(&self) -> CardHealth {
        match self.card.load(Ordering::Relaxed) {
            1 => CardHealth::Logging,
            2 => CardHealth::Unusable,
            3 => CardHealth::Full,
            _ => CardHealth::Absent,
        }
    }

    /// Asks the writer to write what is queued, close the file and return
    /// (end of a replayed ride, or a shutdown on the board).
    pub fn request_stop(&self) {
        self.stop.store(1, Ordering::Release);
    }

    /// Whether a stop was requested.
    pub fn stop_requested(&self) -> bool {
        self.stop.load(Ordering::Acquire) != 0
    }

    /// The supply fell below the power-fail threshold (`low`), or came
    /// back above it: the board's power-voltage-detector interrupt on both
    /// edges. While it is low the writer closes the log and leaves the card
    /// alone (`app::writer`).
    pub fn set_power_low(&self, low: bool) {
        // Bit 0: low now; bits 1..: the falls counted.
        let _ = self
            .power
            .fetch_update(Ordering::AcqRel, Ordering::Acquire, |p| {
                let falls = p >> 1;
                Some(match (low, p & 1 == 1) {
                    (true, false) => (falls.saturating_add(1) << 1) | 1,
                    (true, true) => p,
                    (false, _) => falls << 1,
                })
            });
    }

    /// Whether the supply is below the power-fail threshold now.
    pub fn power_low(&self) -> bool {
        self.power.load(Ordering::Acquire) & 1 == 1
    }

    /// How often the supply fell below the threshold since boot.
    pub fn power_falls(&self) -> u32 {
        self.power.load(Ordering::Acquire) >> 1
    }

    /// The writer finished an iteration of `ops` card operations that kept
    /// it busy `busy_us`; `logging`: a file was open when it began (else it
    /// opened a card, or tried to).
    pub fn note_writer_iteration(&self, logging: bool, ops: u32, busy_us: u64) {
        let max = if logging {
            &self.writer_ops_max
        } else {
            &self.writer_open_ops_max
        };
        max.fetch_max(ops, Ordering::Relaxed);
        let busy = u32::try_from(busy_us).unwrap_or(u32::MAX);
        self.writer_busy_max_us.fetch_max(busy, Ordering::Relaxed);
    }

    /// The writer's worst iterations since boot.
    pub fn writer(&self) -> WriterFigures {
        WriterFigures {
            ops_max: self.writer_ops_max.load(Ordering::Relaxed),
            open_ops_max: self.writer_open_ops_max.load(Ordering::Relaxed),
            busy_max_us: self.writer_busy_max_us.load(Ordering::Relaxed),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::{Frame, FrameStatus, Marker};
    use proptest::prelude::*;

    fn frame(t_us: u64) -> Record<'static> {
        Record::Frame(Frame {
            t_us,
            accel: [0; 3],
            gyro: [0; 3],
            steer_cdeg: 0,
            wheel_count: 0,
            wheel_edge_age_us: 0,
            speed_mm_s: 0,
            status: FrameStatus(0),
        })
    }

    /// The writer's side: takes everything queued, noting each frame with
    /// the frames reported lost before it.
    fn drain(q: &RecordQueue, delivered: &mut Vec<(u64, u64)>, lost: &mut u64) {
        while let Some(r) = q.try_pop() {
            match r {
                Record::Frame(f) => delivered.push((f.t_us, *lost)),
                Record::Dropout(d) => *lost += u64::from(d.frames_lost),
                _ => {}
            }
        }
    }

    proptest! {
        /// A writer that stalls for any stretch: every frame is either
        /// delivered in order or counted in a dropout record that comes
        /// before the next delivered frame; nothing is lost silently.
        #[test]
        fn stalls_lose_nothing_silently(stalls in proptest::collection::vec((10u64..300, 0u64..2000), 1..6)) {
            let q = RecordQueue::new();
            let mut delivered = Vec::new();
            let mut lost = 0u64;
            let mut t = 0u64;
            for &(run_ms, stall_ms) in &stalls {
                for _ in 0..run_ms / 10 {
                    q.push(frame(t));
                    t += 10_000;
                    drain(&q, &mut delivered, &mut lost);
                }
                for _ in 0..stall_ms / 10 {
                    q.push(frame(t));
                    t += 10_000;
                }
            }
            q.push(frame(t));
            t += 10_000;
            drain(&q, &mut delivered, &mut lost);
            let total = t / 10_000;
            prop_assert_eq!(delivered.len() as u64 + lost + u64::from(q.frames_dropped_pending()), total);
            // Each delivered frame's index = frames before it delivered + lost before it.
            for (i, &(t_us, lost_before)) in delivered.iter().enumerate() {
                prop_assert_eq!(t_us / 10_000, i as u64 + lost_before);
            }
            let max_stall_ms = stalls.iter().map(|s| s.1).max().unwrap_or(0);
            if max_stall_ms / 10 < QUEUE_LEN as u64 {
                prop_assert_eq!(lost, 0);
            }
            prop_assert!(q.high_water() as usize <= QUEUE_LEN);
        }

        /// Frames from the sampler mixed with other records (GPS fixes,
        /// alerts, faults: here markers numbered in push order) while the
        /// writer stalls: a dropped frame is counted in a dropout before the
        /// next delivered frame, a dropped other record in
        /// `others_dropped`, never as a lost frame; each kind keeps its
        /// order.
        #[test]
        fn mixed_records_are_accounted_by_kind(
            bursts in proptest::collection::vec(
                (proptest::collection::vec(0u8..4, 0..400), prop::bool::ANY), 1..6),
        ) {
            let q = RecordQueue::new();
            let (mut frames, mut others) = (0u64, 0u16);
            let mut delivered_frames = Vec::new();
            let mut delivered_others = Vec::new();
            let mut lost = 0u64;
            let mut writer = |q: &RecordQueue, lost: &mut u64| {
                while let Some(r) = q.try_pop() {
                    match r {
                        Record::Frame(f) => delivered_frames.push((f.t_us / 10_000, *lost)),
                        Record::Dropout(d) => *lost += u64::from(d.frames_lost),
                        Record::Marker(m) => delivered_others.push(m.id),
                        other => panic!("unexpected {other:?}"),
                    }
                }
            };
            // Each burst is pushed while the writer stalls (up to three
            // queues' worth), then the writer drains or stays stalled.
            for (kinds, drain) in &bursts {
                for &kind in kinds {
                    // One frame in four pushes, the rest other records.
                    if kind == 0 {
                        q.push(frame(frames * 10_000));
                        frames += 1;
                    } else {
                        q.push(Record::Marker(Marker { t_us: frames * 10_000, id: others }));
                        others += 1;
                    }
                }
                if *drain {
                    writer(&q, &mut lost);
                }
            }
            q.push(frame(frames * 10_000));
            frames += 1;
            writer(&q, &mut lost);
            prop_assert_eq!(
                delivered_frames.len() as u64 + lost + u64::from(q.frames_dropped_pending()),
                frames
            );
            for (i, &(index, lost_before)) in delivered_frames.iter().enumerate() {
                prop_assert_eq!(index, i as u64 + lost_before);
            }
            prop_assert_eq!(
                delivered_others.len() as u64 + u64::from(q.others_dropped()),
                u64::from(others)
            );
            prop_assert!(delivered_others.windows(2).all(|w| w[0] < w[1]));
        }
    }

    /// Pushes `seconds_us` of the highest record rate (100 frames and 25
    /// other records a second) into `q` without draining it; returns how
    /// many records were pushed.
    fn fill_at_highest_rate(q: &RecordQueue, stall_us: u64) -> u64 {
        let mut pushed = 0u64;
        for k in 0..stall_us / 10_000 {
            q.push(frame(k * 10_000));
            pushed += 1;
            if k % 4 == 0 {
                q.push(Record::Marker(Marker {
                    t_us: k * 10_000,
                    id: k as u16,
                }));
                pushed += 1;
            }
        }
        pushed
    }

    /// The worst writer iteration (every operation at the SD
    /// specification's longest busy time, at least 4 s) at the highest
    /// record rate: nothing is dropped. Half a second more is: the queue is
    /// what bounds it.
    #[test]
    fn the_worst_writer_iteration_loses_no_record() {
        let stall = WORST_ITERATION_US.max(MIN_QUEUE_US);
        let q = RecordQueue::new();
        let pushed = fill_at_highest_rate(&q, stall);
        assert!(pushed >= MAX_RECORDS_PER_S * stall / 1_000_000);
        assert_eq!(q.len() as u64, pushed);
        assert_eq!((q.frames_dropped_pending(), q.others_dropped()), (0, 0));
        assert_eq!(q.high_water() as u64, pushed);

        let q = RecordQueue::new();
        fill_at_highest_rate(&q, stall + 500_000);
        assert_eq!(q.len(), QUEUE_LEN);
        assert!(q.frames_dropped_pending() > 0);
    }

    /// The sizing arithmetic of the module docs.
    #[test]
    fn queue_sizing_arithmetic() {
        // 576 records at 125 a second: 4.608 s.
        assert_eq!(QUEUE_HOLDS_US, 4_608_000);
        // 8 writes at 0.5 s and 5 reads at 0.1 s.
        assert_eq!(WORST_ITERATION_US, 4_500_000);
        assert_eq!(records_for(WORST_ITERATION_US, MAX_RECORDS_PER_S), 563);
        let one_each = CardOps {
            reads: 1,
            writes: 1,
            other: 1,
        };
        assert_eq!(iteration_stall_us(one_each), 700_000);
        assert_eq!(iteration_stall_us(CardOps::default()), 0);
        assert_eq!(queue_holds_us(200, 125), 1_600_000);
        assert_eq!(queue_holds_us(1, 0), u64::MAX);
        // 4 s at 125 records a second: 500 records; 1 µs more: 501.
        assert_eq!(records_for(4_000_000, 125), 500);
        assert_eq!(records_for(4_000_001, 125), 501);
        assert_eq!(records_for(0, 125), 0);
        assert!(records_for(WORST_ITERATION_US, MAX_RECORDS_PER_S) <= QUEUE_LEN as u64);
        assert!(records_for(MIN_QUEUE_US, MAX_RECORDS_PER_S) <= QUEUE_LEN as u64);
    }

    /// The writer's figures keep the worst of each kind of iteration.
    #[test]
    fn writer_figures_keep_the_worst_iteration_of_each_kind() {
        let s = SharedStatus::new();
        assert_eq!(s.writer(), WriterFigures::default());
        s.note_writer_iteration(false, 40, 700_000);
        s.note_writer_iteration(true, 3, 1_000);
        s.note_writer_iteration(true, 7, 20_000);
        s.note_writer_iteration(true, 2, 500);
        s.note_writer_iteration(false, 12, 100);
        assert_eq!(
            s.writer(),
            WriterFigures {
                ops_max: 7,
                open_ops_max: 40,
                busy_max_us: 700_000
            }
        );
        s.note_writer_iteration(true, 1, u64::MAX);
        assert_eq!(s.writer().busy_max_us, u32::MAX);
    }

    /// The writer stops once `is_empty` says everything queued is on its
    /// way: `len` and `is_empty` follow every push and pop, up to full; the
    /// high-water mark (the status report's) is the fullest it has been.
    #[test]
    fn len_and_is_empty_follow_pushes_and_pops() {
        let q = RecordQueue::new();
        assert_eq!((q.len(), q.is_empty(), q.high_water()), (0, true, 0));
        for n in 1..=QUEUE_LEN {
            assert!(q.push(frame(n as u64)));
            assert!(!q.is_empty() && q.len() == n);
            assert_eq!(q.high_water() as usize, n);
        }
        for n in (0..QUEUE_LEN).rev() {
            assert!(q.try_pop().is_some());
            assert_eq!((q.len(), q.is_empty()), (n, n == 0));
            assert_eq!(q.high_water() as usize, QUEUE_LEN);
        }
    }

    /// The case the property must reach: the queue full when both kinds
    /// arrive.
    #[test]
    fn a_dropped_other_record_is_not_a_lost_frame() {
        let q = RecordQueue::new();
        for t in 0..QUEUE_LEN as u64 {
            assert!(q.push(frame(t)));
        }
        assert!(!q.push(Record::Marker(Marker { t_us: 1, id: 1 })));
        assert_eq!((q.others_dropped(), q.frames_dropped_pending()), (1, 0));
        assert!(!q.push(frame(QUEUE_LEN as u64)));
        assert_eq!((q.others_dropped(), q.frames_dropped_pending()), (1, 1));
        while q.try_pop().is_some() {}
        assert!(q.push(frame(QUEUE_LEN as u64 + 1)));
        match q.try_pop() {
            Some(Record::Dropout(d)) => assert_eq!(d.frames_lost, 1),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn power_falls_are_counted_once_each() {
        let s = SharedStatus::new();
        assert!(!s.power_low());
        s.set_power_low(true);
        s.set_power_low(true);
        assert!(s.power_low());
        assert_eq!(s.power_falls(), 1);
        s.set_power_low(false);
        assert!(!s.power_low());
        s.set_power_low(false);
        s.set_power_low(true);
        assert_eq!((s.power_low(), s.power_falls()), (true, 2));
    }

    /// The sampler sees the writer's card as the logger stands: an exFAT
    /// card is not shown as a missing one.
    #[test]
    fn the_card_is_shared_as_the_logger_stands() {
        use crate::logger::LoggerState;
        let shared = SharedStatus::new();
        assert_eq!(shared.card(), CardHealth::Absent);
        for (state, want) in [
            (LoggerState::Logging { run: 3 }, CardHealth::Logging),
            (LoggerState::UnusableCard, CardHealth::Unusable),
            (LoggerState::CardFull, CardHealth::Full),
            (LoggerState::NoCard, CardHealth::Absent),
        ] {
            shared.set_card(state.into());
            assert_eq!(shared.card(), want);
        }
    }
}
