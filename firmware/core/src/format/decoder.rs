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
//!
//! A valid block is decoded unless it is a copy of one decoded shortly
//! before (or an earlier flush of one): blocks are told apart by content
//! ([`super::recent`]), never by sequence number alone. [`Decoder::feed`]
//! decodes in file order; a reader that can seek decodes in sequence
//! order instead: [`Decoder::scan`] finds the valid blocks and the skipped
//! bytes, then [`Decoder::decode_block`] takes the blocks in order.

use super::block::{Block, BlockError, BlockHeader, BLOCK_LEN, MAGIC, PAYLOAD_LEN};
use super::codec::{RecordError, Records};
use super::crc_window::CrcWindow;
use super::limits::DEFAULT_SAMPLE_RATE_HZ;
use super::recent::{Recent, Seen};
use super::record::{Frame, Record};

/// A forward step between frames longer than the frames known to be
/// missing explain, by more than this, is a time jump (µs).
pub const TIME_JUMP_SLACK_US: u64 = 1_000_000;

/// Consecutive frame steps (no loss, no jump between them) compared with
/// the stated frame period ...
pub const SPACING_WINDOW: u32 = 100;
/// ... of which this many off the period by more than 5 % mean the log
/// info's sample rate contradicts the frames (jitter or an odd gap does not).
pub const SPACING_OFF_MIN: u32 = 90;

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
    /// A valid block that is a copy of one already decoded, or an earlier
    /// flush of one: its records were decoded once.
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
    /// Frames spaced unlike the log info's sample rate says (reported once
    /// per log): readers that take the stated rate are off by the ratio.
    FrameSpacing {
        /// The rate the log info states, Hz.
        stated_hz: u16,
        /// The average spacing of the frames that contradict it, µs.
        spacing_us: u32,
    },
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
    /// Blocks whose sequence number did not follow the highest one before
    /// them (reordered or copied data, or two blocks with one number).
    pub out_of_order_blocks: u64,
    /// Of those, copies of a decoded block (or earlier flushes of one),
    /// skipped: their records were decoded once.
    pub repeated_blocks: u64,
    /// Flushed blocks met again in a fuller version: the new records were
    /// decoded, the block counted once.
    pub rewritten_blocks: u64,
    /// Values the firmware cannot have written, dropped or replaced.
    pub out_of_range: u64,
    /// Whole blocks of zeros at block offsets: space reserved ahead of the
    /// data or never written (`FORMAT.md`, "Unwritten space"), holding
    /// nothing. Not skipped bytes: a block missing from the sequence is
    /// still a gap.
    pub unwritten_blocks: u64,
}

/// What the decoder remembers of the valid block numbered highest so far.
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
    /// The blocks decoded last, to recognise copies and rewrites.
    recent: Recent,
    /// Frame steps compared with the stated period in this window, those
    /// off it, and the sum of those; whether a contradiction was reported.
    spacing: (u32, u32, u64, bool),
    /// The sample rate the log info states (0: none yet).
    stated_hz: u16,
    /// The sequence number of the last valid block walked over, and whether
    /// one of them did not follow the one before it.
    walked_seq: Option<u32>,
    disordered: bool,
}

/// What [`Decoder::decode_block`] did with a block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Its records were decoded (all of them, or those a flushed version
    /// of it did not hold).
    Decoded,
    /// A copy of a block decoded already: nothing was decoded. The caller
    /// reports its bytes ([`Decoder::skipped`]) as [`SkipCause::Repeated`].
    Repeated,
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

    /// Whether the sequence numbers of the valid blocks walked over so far
    /// (by [`Self::feed`] or [`Self::scan`]) strictly increase: then a
    /// decode in file order is a decode in sequence order.
    #[must_use]
    pub fn in_sequence_order(&self) -> bool {
        !self.disordered
    }

    /// Decodes what it can of `chunk`, the bytes of the stream from the first
    /// byte not yet consumed, in file order. Returns how many bytes it
    /// consumed; the caller passes the rest again, followed by more data.
    /// With `at_end` the chunk is the end of the stream and everything is
    /// consumed.
    pub fn feed<'c>(
        &mut self,
        chunk: &'c [u8],
        at_end: bool,
        visit: &mut impl FnMut(Event<'c>),
    ) -> usize {
        self.walk(chunk, at_end, visit, &mut |dec, _, header, block| {
            Some(dec.recent.see(header, header.payload(block)))
        })
    }

    /// The first pass of a decode in sequence order: finds the valid blocks
    /// of `chunk` (passed to `found` with their stream offsets) and reports
    /// and counts the bytes between them, without decoding any block.
    /// Consumes like [`Self::feed`].
    pub fn scan<'c>(
        &mut self,
        chunk: &'c [u8],
        at_end: bool,
        visit: &mut impl FnMut(Event<'c>),
        found: &mut impl FnMut(u64, &BlockHeader),
    ) -> usize {
        self.walk(chunk, at_end, visit, &mut |_, offset, header, _| {
            found(offset, header);
            None
        })
    }

    /// Decodes one valid block (at stream offset `offset`, for messages),
    /// after the ones decoded before it: the second pass of a decode in
    /// sequence order. A block that is not valid is reported as skipped.
    pub fn decode_block<'b>(
        &mut self,
        offset: u64,
        block: &'b Block,
        visit: &mut impl FnMut(Event<'b>),
    ) -> Outcome {
        match BlockHeader::parse(block) {
            Ok(header) => {
                let seen = self.recent.see(&header, header.payload(block));
                self.block(&header, block, seen, visit);
                if seen == Seen::Repeat {
                    Outcome::Repeated
                } else {
                    Outcome::Decoded
                }
            }
            Err(err) => {
                self.skipped(offset, BLOCK_LEN as u64, cause_of(err), visit);
                Outcome::Decoded
            }
        }
    }

    /// Reports and counts `len` bytes from `offset` skipped for `cause`.
    pub fn skipped<'c>(
        &mut self,
        offset: u64,
        len: u64,
        cause: SkipCause,
        visit: &mut impl FnMut(Event<'c>),
    ) {
        self.stats.bytes_skipped += len;
        visit(Event::Skipped { offset, len, cause });
    }

    /// Finds the valid blocks of `chunk`, hands each to `on_block` (which
    /// says what it is to the blocks before it, if it is to be decoded),
    /// decodes those, and reports the bytes between them (repeats included).
    fn walk<'c>(
        &mut self,
        chunk: &'c [u8],
        at_end: bool,
        visit: &mut impl FnMut(Event<'c>),
        on_block: &mut impl FnMut(&mut Self, u64, &BlockHeader, &'c Block) -> Option<Seen>,
    ) -> usize {
        let mut pos = 0;
        // A stretch of bytes being skipped (from this stream offset),
        // reported once it ends.
        let mut skip: Option<(u64, SkipCause)> = self.open_skip.take();
        let base = self.offset;
        let at = |pos: usize| base + pos as u64;
        // Candidates a few bytes apart get their CRCs rolled from the last.
        let mut crc = CrcWindow::default();
        while chunk.len() - pos >= BLOCK_LEN {
            let block = as_block(&chunk[pos..]);
            if at(pos) % BLOCK_LEN as u64 == 0 && is_unwritten(block) {
                self.flush_skip(&mut skip, chunk, pos, visit);
                self.stats.unwritten_blocks += 1;
                pos += BLOCK_LEN;
                continue;
            }
            let parsed = if block[..MAGIC.len()] == MAGIC {
                BlockHeader::parse_with_crc(block, crc.crc_at(chunk, pos))
            } else {
                Err(BlockError::BadMagic)
            };
            match parsed {
                Ok(header) => {
                    self.disordered |= self.walked_seq.is_some_and(|seq| header.seq <= seq);
                    self.walked_seq = Some(header.seq);
                    let seen = on_block(self, at(pos), &header, block);
                    if seen == Some(Seen::Repeat) {
                        if skip.is_some_and(|(_, c)| c != SkipCause::Repeated) {
                            self.flush_skip(&mut skip, chunk, pos, visit);
                        }
                        skip.get_or_insert((at(pos), SkipCause::Repeated));
                    } else {
                        self.flush_skip(&mut skip, chunk, pos, visit);
                    }
                    if let Some(seen) = seen {
                        self.block(&header, block, seen, visit);
                    }
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
                    pos = next_unwritten(chunk, base, pos, next_marker(chunk, pos + 1));
                }
            }
        }
        if at_end && pos < chunk.len() {
            if skip.is_some_and(|(_, c)| c == SkipCause::Repeated) {
                self.flush_skip(&mut skip, chunk, pos, visit);
            }
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

    /// Decodes a valid block `seen` relates so to the blocks before it:
    /// a repeat is only counted, a fuller rewrite gives only the records
    /// its flushed version did not hold.
    fn block<'c>(
        &mut self,
        header: &BlockHeader,
        block: &'c Block,
        seen: Seen,
        visit: &mut impl FnMut(Event<'c>),
    ) {
        let decoded_len = match seen {
            Seen::Repeat => {
                self.stats.out_of_order_blocks += 1;
                self.stats.repeated_blocks += 1;
                return;
            }
            Seen::New => {
                self.stats.blocks += 1;
                self.account_gap(header, visit);
                0
            }
            Seen::Fuller { decoded_len } => {
                self.stats.rewritten_blocks += 1;
                decoded_len
            }
        };
        let payload = header.payload(block);
        let mut frames = 0u32;
        let mut records = Records::new(payload, header.t0_us);
        loop {
            let old = records.offset() < decoded_len;
            if let Some(frame) = records.next_frame() {
                frames += 1;
                if !old {
                    self.frame(header.seq, frame, visit);
                }
                continue;
            }
            // Any other record, or a record that cannot be read (frames
            // that read whole never come here).
            let Some(item) = records.next() else { break };
            if old {
                continue;
            }
            match item {
                Ok(mut record) => {
                    self.stats.records += 1;
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
        let mut prefix = Records::new(&payload[..decoded_len.min(payload.len())], header.t0_us);
        prefix.by_ref().for_each(drop);
        self.stats.unknown_records += u64::from(
            records
                .skipped_unknown()
                .saturating_sub(prefix.skipped_unknown()),
        );
        if self.last.is_none_or(|last| header.seq >= last.seq) {
            self.last = Some(Last {
                seq: header.seq,
                frames_end: header.first_frame.wrapping_add(frames),
            });
        }
    }

    /// Passes on a new frame of block `seq`, checking its time (a frame
    /// holds no value the firmware cannot have written).
    #[inline(always)]
    fn frame<'c>(&mut self, seq: u32, frame: Frame, visit: &mut impl FnMut(Event<'c>)) {
        self.stats.records += 1;
        self.stats.frames += 1;
        self.check_time(seq, frame.t_us, visit);
        visit(Event::Record(Record::Frame(frame)));
    }

    /// Reports a frame at `t_us` that jumps back, or forward by more than
    /// the frames known to be missing explain.
    fn check_time<'c>(&mut self, seq: u32, t_us: u64, visit: &mut impl FnMut(Event<'c>)) {
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
            } else if self.frames_missing == 0 && self.period_us != 0 {
                self.check_spacing(seq, t_us - prev, visit);
            }
        }
        self.last_frame_us = Some(t_us);
        self.frames_missing = 0;
    }

    /// Compares one frame step with the stated period; reports, once, a
    /// window of steps that mostly contradict it.
    fn check_spacing<'c>(&mut self, seq: u32, step_us: u64, visit: &mut impl FnMut(Event<'c>)) {
        let (steps, off, off_sum, reported) = &mut self.spacing;
        if *reported {
            return;
        }
        *steps += 1;
        if step_us.abs_diff(self.period_us).saturating_mul(20) > self.period_us {
            *off += 1;
            *off_sum = off_sum.saturating_add(step_us);
        }
        if *steps < SPACING_WINDOW {
            return;
        }
        if *off >= SPACING_OFF_MIN {
            *reported = true;
            let what = OutOfRange::FrameSpacing {
                stated_hz: self.stated_hz,
                spacing_us: u32::try_from(*off_sum / u64::from(*off)).unwrap_or(u32::MAX),
            };
            self.stats.out_of_range += 1;
            visit(Event::OutOfRange { seq, what });
        }
        (*steps, *off, *off_sum) = (0, 0, 0);
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
                self.stated_hz = info.sample_rate_hz;
                let reported = self.spacing.3;
                self.spacing = (0, 0, 0, reported);
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

/// Position of the next sync marker at or after `from` that can start a
/// block, or the point from which fewer than a block's bytes remain (the
/// caller then needs more data).
///
/// A marker whose payload length field exceeds the payload area cannot
/// start a valid block whatever its CRC, so it is passed over without
/// one: a stretch of back-to-back markers costs a memchr search, not a
/// CRC per marker.
fn next_marker(chunk: &[u8], from: usize) -> usize {
    let limit = chunk.len().saturating_sub(BLOCK_LEN - 1);
    if from >= limit {
        return limit.max(from.min(chunk.len()));
    }
    // One searcher for the whole stretch: a flood of markers costs one
    // setup, not one per marker.
    let window = &chunk[from..limit + MAGIC.len() - 1];
    memchr::memmem::find_iter(window, &MAGIC)
        .map(|i| from + i)
        .find(|&at| usize::from(u16::from_le_bytes([chunk[at + 6], chunk[at + 7]])) <= PAYLOAD_LEN)
        .unwrap_or(limit)
}

/// Whether `block` is all zeros: reserved or never written.
fn is_unwritten(block: &Block) -> bool {
    block.iter().all(|&b| b == 0)
}

/// The first block of zeros at a block offset (of the stream, whose byte
/// `base` is `chunk[0]`) after `pos` and before `next`, else `next`:
/// unwritten space after a damaged block ends its skipped stretch.
fn next_unwritten(chunk: &[u8], base: u64, pos: usize, next: usize) -> usize {
    let len = BLOCK_LEN as u64;
    // Stream offset of `chunk[pos]`, rounded up past `pos` to a block offset.
    let first = ((base + pos as u64) / len + 1) * len - base;
    usize::try_from(first)
        .ok()
        .into_iter()
        .flat_map(|first| (first..next).step_by(BLOCK_LEN))
        .take_while(|&p| p + BLOCK_LEN <= chunk.len())
        .find(|&p| is_unwritten(as_block(&chunk[p..])))
        .unwrap_or(next)
}

fn as_block(bytes: &[u8]) -> &Block {
    // The caller checked there are at least BLOCK_LEN bytes.
    bytes[..BLOCK_LEN].try_into().unwrap_or(&[0; BLOCK_LEN])
}
