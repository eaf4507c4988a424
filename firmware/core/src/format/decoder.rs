//! Streaming decoder: finds valid blocks in a byte stream, resynchronises
//! after damage, and reports exactly what was lost.
//!
//! Blocks are expected at 512-byte steps. When the bytes at the expected
//! place are not a valid block (bad CRC, garbage, a missing stretch), the
//! decoder searches byte by byte for the next sync marker whose block passes
//! its CRC. What was lost is computed from the headers on either side: the
//! sequence numbers give the blocks, the frame counters give the frames, the
//! time bases give the time span. Memory use is fixed; the caller feeds
//! chunks of any size.

use super::block::{Block, BlockError, BlockHeader, BLOCK_LEN, MAGIC};
use super::codec::{RecordError, Records};
use super::limits::DEFAULT_SAMPLE_RATE_HZ;
use super::record::Record;

/// A block at most this many numbers behind the last one decoded, out of
/// its place, is a repeat or a stale copy. One much further behind means the
/// earlier block was the odd one (a crafted or stray block numbered high),
/// so it is decoded: a bad block in front can hide at most this many.
pub const REPEAT_WINDOW_BLOCKS: u32 = 64;

/// A forward step between frames longer than the frames known to be
/// missing explain, by more than this, is a time jump (µs).
pub const TIME_JUMP_SLACK_US: u64 = 1_000_000;

/// A stretch of missing data between two valid blocks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Gap {
    /// Sequence number of the first missing block.
    pub first_seq: u32,
    /// Number of missing blocks.
    pub blocks: u32,
    /// Number of frames those blocks held.
    pub frames: u32,
    /// Time of the last frame before the gap (`None` at the start of a file).
    pub from_us: Option<u64>,
    /// Time base of the first block after the gap.
    pub to_us: u64,
}

/// Why bytes were skipped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SkipCause {
    /// A block marker was there but the block failed its CRC.
    Damaged,
    /// A valid block written by an incompatible major version.
    UnsupportedVersion(u8),
    /// A block whose CRC matched but whose header is inconsistent.
    BadHeader,
    /// Bytes that are not a block at all.
    Garbage,
    /// The file ends inside a block.
    TruncatedTail,
    /// A valid block that repeats or predates one already decoded, out of
    /// its place in the file: its records were already counted, or are stale.
    Repeated,
}

/// A value in a CRC-valid record that the firmware cannot have written
/// (see [`super::limits`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum OutOfRange {
    /// The log info's sample rate; the record is passed on with the
    /// documented default instead.
    SampleRate(u16),
    /// Fields of a GPS fix (this many), removed from the fix passed on.
    GpsFields(u32),
    /// A UTC sync record outside 2000-2099; the record is dropped.
    UtcSync,
}

/// Something the decoder found, in file order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event<'a> {
    /// A record of a valid block.
    Record(Record<'a>),
    /// Blocks missing before the next valid block.
    Gap(Gap),
    /// Bytes that were not part of any valid block.
    Skipped {
        /// File offset of the first skipped byte.
        offset: u64,
        /// Number of bytes skipped.
        len: u64,
        /// Why.
        cause: SkipCause,
    },
    /// A block passed its CRC but a record in it could not be read; the
    /// rest of that block is lost.
    BadRecord {
        /// Sequence number of the block.
        seq: u32,
        /// What was wrong.
        error: RecordError,
    },
    /// A value the firmware cannot have written, dropped or replaced.
    OutOfRange {
        /// Sequence number of the block.
        seq: u32,
        /// What was out of range.
        what: OutOfRange,
    },
    /// Consecutive frames whose time goes backwards, or forwards by more
    /// than the frames known to be missing explain: the frames after it
    /// are a new segment of the run.
    TimeJump {
        /// Time of the previous frame.
        from_us: u64,
        /// Time of this frame.
        to_us: u64,
    },
}

/// Running totals of a decode.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DecodeStats {
    /// Valid blocks decoded.
    pub blocks: u64,
    /// Records decoded.
    pub records: u64,
    /// Frames decoded.
    pub frames: u64,
    /// Blocks missing (sum over gaps).
    pub blocks_lost: u64,
    /// Frames in missing blocks (sum over gaps).
    pub frames_lost: u64,
    /// Places where a damaged block (marker present, CRC wrong) was skipped.
    pub damaged_blocks: u64,
    /// Bytes that were not part of a valid block.
    pub bytes_skipped: u64,
    /// Records in valid blocks that could not be read.
    pub bad_records: u64,
    /// Length-prefixed records of unknown kinds skipped.
    pub unknown_records: u64,
    /// Frames whose time went backwards.
    pub time_jumps: u64,
    /// Frames whose time went forwards by more than missing frames explain.
    pub forward_time_jumps: u64,
    /// Blocks whose sequence number did not follow (stale or reordered data).
    pub out_of_order_blocks: u64,
    /// Of those, blocks skipped as repeats or stale copies (out of their
    /// place in the file and not after the last block decoded).
    pub repeated_blocks: u64,
    /// Values the firmware cannot have written, dropped or replaced.
    pub out_of_range: u64,
}

/// What the decoder remembers of the last valid block.
#[derive(Clone, Copy, Debug)]
struct Last {
    seq: u32,
    frames_end: u32,
}

/// The streaming decoder.
#[derive(Clone, Debug, Default)]
pub struct Decoder {
    stats: DecodeStats,
    last: Option<Last>,
    last_frame_us: Option<u64>,
    /// Frames known to be missing since the last frame: in lost blocks or
    /// reported dropped by the logger.
    frames_missing: u64,
    /// The frame period stated by the log info, µs (0: not yet known).
    period_us: u64,
    /// Offset in the stream of the next byte the decoder will look at.
    offset: u64,
    /// A stretch of skipped bytes still open when the last chunk ended:
    /// its first byte's stream offset and why. Reported once it ends, so
    /// one damaged stretch is one event whatever the chunks.
    open_skip: Option<(u64, SkipCause)>,
}

impl Decoder {
    /// A decoder at the start of a file.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Totals so far (a stretch of skipped bytes counts once it ends: at
    /// the next valid block, or at the end of the stream).
    #[must_use]
    pub fn stats(&self) -> &DecodeStats {
        &self.stats
    }

    /// Decodes what it can of `chunk`, the bytes of the stream from the first
    /// byte not yet consumed. Returns how many bytes it consumed; the caller
    /// passes the rest again, followed by more data. With `at_end` the chunk
    /// is the end of the stream and everything is consumed.
    pub fn feed<'c>(
        &mut self,
        chunk: &'c [u8],
        at_end: bool,
        visit: &mut impl FnMut(Event<'c>),
    ) -> usize {
        let mut pos = 0;
        // A stretch of bytes being skipped (from this stream offset),
        // reported once it ends.
        let mut skip: Option<(u64, SkipCause)> = self.open_skip.take();
        let base = self.offset;
        let at = |pos: usize| base + pos as u64;
        while chunk.len() - pos >= BLOCK_LEN {
            let block = as_block(&chunk[pos..]);
            match BlockHeader::parse(block) {
                Ok(header) if self.is_repeat(&header, pos) => {
                    self.stats.out_of_order_blocks += 1;
                    self.stats.repeated_blocks += 1;
                    if skip.is_some_and(|(_, c)| c != SkipCause::Repeated) {
                        self.flush_skip(&mut skip, chunk, pos, visit);
                    }
                    skip.get_or_insert((at(pos), SkipCause::Repeated));
                    pos += BLOCK_LEN;
                }
                Ok(header) => {
                    self.flush_skip(&mut skip, chunk, pos, visit);
                    self.block(&header, block, visit);
                    pos += BLOCK_LEN;
                }
                Err(err) => {
                    if skip.is_some_and(|(_, c)| c == SkipCause::Repeated) {
                        self.flush_skip(&mut skip, chunk, pos, visit);
                    }
                    if skip.is_none() {
                        skip = Some((at(pos), cause_of(err)));
                        if err == BlockError::BadCrc {
                            self.stats.damaged_blocks += 1;
                        }
                    }
                    pos = next_marker(chunk, pos + 1);
                }
            }
        }
        if at_end && pos < chunk.len() {
            skip.get_or_insert((at(pos), SkipCause::TruncatedTail));
            pos = chunk.len();
        }
        if at_end {
            self.flush_skip(&mut skip, chunk, pos, visit);
        } else {
            self.open_skip = skip;
        }
        self.offset += pos as u64;
        pos
    }

    fn flush_skip<'c>(
        &mut self,
        skip: &mut Option<(u64, SkipCause)>,
        chunk: &'c [u8],
        end: usize,
        visit: &mut impl FnMut(Event<'c>),
    ) {
        let Some((start, cause)) = skip.take() else {
            return;
        };
        let len = self.offset + end.min(chunk.len()) as u64 - start;
        if len == 0 {
            return;
        }
        self.stats.bytes_skipped += len;
        visit(Event::Skipped {
            offset: start,
            len,
            cause,
        });
    }

    fn block<'c>(
        &mut self,
        header: &BlockHeader,
        block: &'c Block,
        visit: &mut impl FnMut(Event<'c>),
    ) {
        self.stats.blocks += 1;
        self.account_gap(header, visit);
        let mut frames = 0u32;
        let mut records = Records::new(header.payload(block), header.t0_us);
        for item in records.by_ref() {
            match item {
                Ok(mut record) => {
                    self.stats.records += 1;
                    if let Record::Frame(f) = &record {
                        frames += 1;
                        self.check_time(f.t_us, visit);
                    }
                    if !self.check_values(header.seq, &mut record, visit) {
                        continue;
                    }
                    visit(Event::Record(record));
                }
                Err(error) => {
                    self.stats.bad_records += 1;
                    visit(Event::BadRecord {
                        seq: header.seq,
                        error,
                    });
                }
            }
        }
        self.stats.frames += u64::from(frames);
        self.stats.unknown_records += u64::from(records.skipped_unknown());
        self.last = Some(Last {
            seq: header.seq,
            frames_end: header.first_frame.wrapping_add(frames),
        });
    }

    /// Whether a valid block at `pos` in the current chunk repeats or
    /// predates what was decoded: not after the last block (and within
    /// [`REPEAT_WINDOW_BLOCKS`] of it), and not at its own place in the file
    /// (block `seq` sits at `seq` x 512; one there is always decoded).
    fn is_repeat(&self, header: &BlockHeader, pos: usize) -> bool {
        let at = self.offset + pos as u64;
        let in_place = u64::from(header.seq) * BLOCK_LEN as u64 == at;
        !in_place
            && self.last.is_some_and(|last| {
                header.seq <= last.seq && last.seq - header.seq < REPEAT_WINDOW_BLOCKS
            })
    }

    /// Reports a frame at `t_us` that jumps back, or forward by more than
    /// the frames known to be missing explain.
    fn check_time<'c>(&mut self, t_us: u64, visit: &mut impl FnMut(Event<'c>)) {
        if let Some(prev) = self.last_frame_us {
            let period = if self.period_us == 0 {
                1_000_000 / u64::from(DEFAULT_SAMPLE_RATE_HZ)
            } else {
                self.period_us
            };
            let explained = self
                .frames_missing
                .saturating_add(1)
                .saturating_mul(period)
                .saturating_add(TIME_JUMP_SLACK_US);
            let jump = if t_us < prev {
                self.stats.time_jumps += 1;
                true
            } else if t_us - prev > explained {
                self.stats.forward_time_jumps += 1;
                true
            } else {
                false
            };
            if jump {
                visit(Event::TimeJump {
                    from_us: prev,
                    to_us: t_us,
                });
            }
        }
        self.last_frame_us = Some(t_us);
        self.frames_missing = 0;
    }

    /// Drops or replaces values the firmware cannot have written, reporting
    /// each; `false` when the whole record is dropped.
    fn check_values<'c>(
        &mut self,
        seq: u32,
        record: &mut Record<'c>,
        visit: &mut impl FnMut(Event<'c>),
    ) -> bool {
        let what = match record {
            Record::LogInfo(info) => {
                let bad = (!info.sample_rate_is_valid()).then(|| {
                    let stated = info.sample_rate_hz;
                    info.sample_rate_hz = DEFAULT_SAMPLE_RATE_HZ;
                    OutOfRange::SampleRate(stated)
                });
                self.period_us = 1_000_000 / u64::from(info.sample_rate_hz);
                bad
            }
            Record::Gps(fix) => match fix.drop_out_of_range() {
                0 => None,
                n => Some(OutOfRange::GpsFields(n)),
            },
            Record::UtcSync(sync) if !sync.is_valid() => Some(OutOfRange::UtcSync),
            Record::Dropout(d) => {
                self.frames_missing = self.frames_missing.saturating_add(d.frames_lost.into());
                None
            }
            _ => None,
        };
        if let Some(what) = what {
            self.stats.out_of_range += 1;
            visit(Event::OutOfRange { seq, what });
        }
        !matches!(what, Some(OutOfRange::UtcSync))
    }

    /// Compares a new block's header with the previous valid block's.
    fn account_gap<'c>(&mut self, header: &BlockHeader, visit: &mut impl FnMut(Event<'c>)) {
        let (expected_seq, frames_end) = match self.last {
            Some(last) => (last.seq.wrapping_add(1), last.frames_end),
            None => (0, 0),
        };
        if header.seq == expected_seq {
            return;
        }
        if header.seq < expected_seq {
            // Not a loss we can size: stale data or a restarted writer.
            self.stats.out_of_order_blocks += 1;
            return;
        }
        let gap = Gap {
            first_seq: expected_seq,
            blocks: header.seq - expected_seq,
            frames: header.first_frame.saturating_sub(frames_end),
            from_us: self.last_frame_us,
            to_us: header.t0_us,
        };
        self.stats.blocks_lost += u64::from(gap.blocks);
        self.stats.frames_lost += u64::from(gap.frames);
        self.frames_missing = self.frames_missing.saturating_add(gap.frames.into());
        visit(Event::Gap(gap));
    }
}

fn cause_of(err: BlockError) -> SkipCause {
    match err {
        BlockError::BadMagic => SkipCause::Garbage,
        BlockError::BadCrc => SkipCause::Damaged,
        BlockError::UnsupportedVersion(v) => SkipCause::UnsupportedVersion(v),
        BlockError::BadLength(_) => SkipCause::BadHeader,
    }
}

/// Position of the next sync marker at or after `from`, or the point from
/// which fewer than a block's bytes remain (the caller then needs more data).
fn next_marker(chunk: &[u8], from: usize) -> usize {
    let limit = chunk.len().saturating_sub(BLOCK_LEN - 1);
    if from >= limit {
        return limit.max(from.min(chunk.len()));
    }
    // The marker's first byte is rare in records; memchr-like scanning on it
    // keeps resynchronisation fast through long garbage.
    let window = &chunk[from..limit + MAGIC.len() - 1];
    window
        .windows(MAGIC.len())
        .position(|w| w == MAGIC)
        .map_or(limit, |i| from + i)
}

fn as_block(bytes: &[u8]) -> &Block {
    // The caller checked there are at least BLOCK_LEN bytes.
    bytes[..BLOCK_LEN].try_into().unwrap_or(&[0; BLOCK_LEN])
}
