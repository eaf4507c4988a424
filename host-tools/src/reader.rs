//! Reading a card log from a file, in bounded memory, with progress.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::ops::ControlFlow;
use std::path::Path;

use indicatif::{ProgressBar, ProgressStyle};
use wobble_core::format::{Block, DecodeStats, Decoder, Event, Outcome, SkipCause, BLOCK_LEN};

use crate::CliError;

/// Bytes read from the file at a time.
const CHUNK_LEN: usize = 1 << 17;
/// Files larger than this get a progress bar (when stderr is a terminal).
const PROGRESS_MIN_LEN: u64 = 64 << 20;

/// Decodes the log at `path`, calling `visit` for every event.
///
/// The log is read twice: a first pass finds its valid blocks; when their
/// sequence numbers do not strictly increase through the file (blocks
/// reordered, copied, or two with one number), the reports of skipped
/// bytes come first and the blocks are then decoded in sequence order
/// (file order among blocks with one number), each unique one once.
/// Otherwise the blocks are decoded in file order. A stream (a pipe,
/// standard input) is copied to a temporary file first
/// ([`crate::spool`]), so it is decoded the same way. Memory use is the
/// chunk size plus, for a reordered log, 16 bytes per block (3 % of the
/// file). A file in which not a single valid
/// block is found is an error: it is not a card log, or nothing of it
/// survived.
pub fn read_log(path: &Path, mut visit: impl FnMut(Event<'_>)) -> Result<DecodeStats, CliError> {
    read_log_until(path, CHUNK_LEN, |event| {
        visit(event);
        ControlFlow::Continue(())
    })
}

/// Decodes the log at `path` like [`read_log`] until `visit` fails (a
/// closed pipe, say): the rest of the file is not read, and its error is
/// the inner result.
///
/// # Errors
/// The log cannot be read.
pub fn read_log_try<E>(
    path: &Path,
    mut visit: impl FnMut(Event<'_>) -> Result<(), E>,
) -> Result<Result<(), E>, CliError> {
    let mut failed = None;
    read_log_until(path, CHUNK_LEN, |event| match visit(event) {
        Ok(()) => ControlFlow::Continue(()),
        Err(e) => {
            failed = Some(e);
            ControlFlow::Break(())
        }
    })?;
    Ok(failed.map_or(Ok(()), Err))
}

/// Decodes the log at `path` like [`read_log`] until `visit` breaks: the
/// rest of the chunk in hand is decoded (and not passed on), the rest of the
/// file is not read. The first chunk is `first_len` bytes, and each one
/// after it twice the last, up to the usual chunk size, so a reader that
/// stops near the start reads little of a large file.
pub fn read_log_until(
    path: &Path,
    first_len: usize,
    mut visit: impl FnMut(Event<'_>) -> ControlFlow<()>,
) -> Result<DecodeStats, CliError> {
    let (mut file, len) = crate::spool::open_seekable(path)?;
    let io = |e| CliError::file(path, e);
    let scan = scan(&mut file, len).map_err(io)?;
    let other_version = scan.skipped.iter().find_map(|&(_, _, cause)| match cause {
        SkipCause::UnsupportedVersion(v) => Some(v),
        _ => None,
    });
    let stats = if scan.in_order {
        file.seek(SeekFrom::Start(0)).map_err(io)?;
        *stream(&mut file, len, first_len, &mut visit)
            .map_err(io)?
            .stats()
    } else {
        in_sequence_order(&mut file, scan, &mut visit).map_err(io)?
    };
    some_blocks(path, len, stats, other_version)
}

/// Decodes the log at `path` like [`read_log_until`] (from the usual
/// chunks), but in one pass when its blocks are in sequence order, as
/// a log written once is: the blocks are decoded in file order as they
/// are found. When the pass shows blocks out of order (or none valid),
/// `restart` is called and the log is decoded again as
/// [`read_log_until`] decodes it: `visit` gets that decode's events from
/// its start. Either way `visit` ends up with the events
/// [`read_log_until`] gives. A `visit` that breaks ends the reading, as
/// there; the log is not read again.
///
/// # Errors
/// As [`read_log_until`].
pub fn read_log_restarting(
    path: &Path,
    mut visit: impl FnMut(Event<'_>) -> ControlFlow<()>,
    restart: impl FnOnce(),
) -> Result<DecodeStats, CliError> {
    let (mut file, len) = crate::spool::open_seekable(path)?;
    let mut stopped = false;
    let mut watched = |event: Event<'_>| {
        let flow = visit(event);
        stopped |= flow.is_break();
        flow
    };
    let decoder =
        stream(&mut file, len, CHUNK_LEN, &mut watched).map_err(|e| CliError::file(path, e))?;
    // A visitor that stopped the pass (Ctrl-C) wants no second one.
    if stopped || (decoder.in_sequence_order() && decoder.stats().blocks > 0) {
        return Ok(*decoder.stats());
    }
    restart();
    read_log_until(path, CHUNK_LEN, visit)
}

/// `stats`, or the error for a log of `len` bytes without a valid block
/// (one of another format version, if the first pass found one).
fn some_blocks(
    path: &Path,
    len: u64,
    stats: DecodeStats,
    other_version: Option<u8>,
) -> Result<DecodeStats, CliError> {
    if stats.blocks == 0 {
        if let Some(v) = other_version {
            return Err(CliError::file(
                path,
                format!(
                    "unsupported format version: its blocks are of format major version {v}, \
                     this wobblog reads version {}",
                    wobble_core::format::block::VERSION_MAJOR
                ),
            ));
        }
        let what = if len == 0 {
            "empty file".to_string()
        } else {
            format!("no valid log block in {len} bytes")
        };
        return Err(CliError::file(
            path,
            format!("{what}: not a wobble-logger log, or entirely damaged"),
        ));
    }
    Ok(stats)
}

/// Decodes `file` in file order, the first chunk `first_len` bytes long.
fn stream(
    file: &mut File,
    len: u64,
    first_len: usize,
    visit: &mut impl FnMut(Event<'_>) -> ControlFlow<()>,
) -> std::io::Result<Decoder> {
    let progress = progress_bar(len, "decoding");
    let mut decoder = Decoder::new();
    let mut buf = vec![0u8; CHUNK_LEN];
    let mut filled = 0;
    // The decoder leaves less than a block unconsumed: two blocks always
    // make progress.
    let mut limit = first_len.clamp(2 * BLOCK_LEN, CHUNK_LEN);
    let mut stopped = false;
    loop {
        filled += fill(file, &mut buf[filled..limit])?;
        let at_end = filled < limit;
        let consumed = decoder.feed(&buf[..filled], at_end, &mut |event| {
            stopped = stopped || visit(event).is_break();
        });
        progress.inc(consumed as u64);
        buf.copy_within(consumed..filled, 0);
        filled -= consumed;
        if at_end || stopped {
            break;
        }
        limit = (2 * limit).min(CHUNK_LEN);
    }
    progress.finish_and_clear();
    Ok(decoder)
}

/// What the first pass over a file found.
struct Scan {
    /// The decoder that made the pass: it has counted the skipped bytes.
    decoder: Decoder,
    /// The skipped stretches, in file order: offset, length, cause.
    skipped: Vec<(u64, u64, SkipCause)>,
    /// Sequence number and offset of every valid block, in file order.
    blocks: Vec<(u32, u64)>,
    /// Whether the sequence numbers strictly increase through the file.
    in_order: bool,
}

/// The first pass: the valid blocks of `file` and the bytes between them.
fn scan(file: &mut File, len: u64) -> std::io::Result<Scan> {
    let progress = progress_bar(len, "indexing");
    let mut decoder = Decoder::new();
    let mut skipped = Vec::new();
    let mut blocks: Vec<(u32, u64)> = Vec::new();
    let mut buf = vec![0u8; CHUNK_LEN];
    let mut filled = 0;
    loop {
        filled += fill(file, &mut buf[filled..])?;
        let at_end = filled < CHUNK_LEN;
        let consumed = decoder.scan(
            &buf[..filled],
            at_end,
            &mut |event| {
                if let Event::Skipped { offset, len, cause } = event {
                    skipped.push((offset, len, cause));
                }
            },
            &mut |offset, header| blocks.push((header.seq, offset)),
        );
        progress.inc(consumed as u64);
        buf.copy_within(consumed..filled, 0);
        filled -= consumed;
        if at_end {
            break;
        }
    }
    progress.finish_and_clear();
    Ok(Scan {
        in_order: decoder.in_sequence_order(),
        decoder,
        skipped,
        blocks,
    })
}

/// The second pass over a reordered file: the skipped stretches, then
/// every valid block in sequence order; copies of a block (now next to it)
/// are reported as skipped, one report per stretch of adjacent copies.
fn in_sequence_order(
    file: &mut File,
    scan: Scan,
    visit: &mut impl FnMut(Event<'_>) -> ControlFlow<()>,
) -> std::io::Result<DecodeStats> {
    let Scan {
        mut decoder,
        skipped,
        mut blocks,
        ..
    } = scan;
    let stopped = std::cell::Cell::new(false);
    let mut pass = |event: Event<'_>| {
        if !stopped.get() && visit(event).is_break() {
            stopped.set(true);
        }
    };
    for (offset, len, cause) in skipped {
        pass(Event::Skipped { offset, len, cause });
    }
    blocks.sort_unstable();
    let mut block: Block = [0; BLOCK_LEN];
    // A stretch of copies not yet reported: offset, length.
    let mut copies: Option<(u64, u64)> = None;
    for (_, offset) in blocks {
        if stopped.get() {
            break;
        }
        file.seek(SeekFrom::Start(offset))?;
        file.read_exact(&mut block)?;
        let mut reported = None;
        let outcome = decoder.decode_block(offset, &block, &mut |event| {
            // A block's events come after the report of the copies before it.
            if let Some((at, len)) = copies.take() {
                pass(Event::Skipped {
                    offset: at,
                    len,
                    cause: SkipCause::Repeated,
                });
                reported = Some((at, len));
            }
            pass(event);
        });
        if let Some((at, len)) = reported {
            // Counted now that the decoder is free again (reported above).
            decoder.skipped(at, len, SkipCause::Repeated, &mut |_| {});
        }
        if outcome == Outcome::Repeated {
            copies = match copies {
                Some((at, len)) if at + len == offset => Some((at, len + BLOCK_LEN as u64)),
                Some((at, len)) => {
                    decoder.skipped(at, len, SkipCause::Repeated, &mut pass);
                    Some((offset, BLOCK_LEN as u64))
                }
                None => Some((offset, BLOCK_LEN as u64)),
            };
        }
    }
    if let Some((at, len)) = copies {
        decoder.skipped(at, len, SkipCause::Repeated, &mut pass);
    }
    Ok(*decoder.stats())
}

/// Reads until `buf` is full or the file ends.
fn fill(file: &mut File, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut total = 0;
    while total < buf.len() {
        match file.read(&mut buf[total..]) {
            Ok(0) => break,
            Ok(n) => total += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(total)
}

fn progress_bar(len: u64, what: &'static str) -> ProgressBar {
    if len < PROGRESS_MIN_LEN {
        return ProgressBar::hidden();
    }
    // indicatif draws nothing when stderr is not a terminal.
    let bar = ProgressBar::new(len);
    if let Ok(style) =
        ProgressStyle::with_template("{msg} {bar:40} {bytes}/{total_bytes} {bytes_per_sec}")
    {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(what);
    bar
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use wobble_core::config::Config;
    use wobble_core::format::header::header_records;
    use wobble_core::format::{BlockEncoder, Frame, LogInfo, Record, SkipCause, EDGE_AGE_NONE};

    /// A log with the default configuration in its header and `frames`
    /// frames after it, behind `garbage` bytes of damage.
    pub(crate) fn log(frames: u64, garbage: usize) -> (tempfile::NamedTempFile, Vec<String>) {
        let mut text = String::new();
        Config::default().write_lines(&mut text).unwrap();
        let lines: Vec<String> = text.lines().map(String::from).collect();
        let info = LogInfo {
            t_us: 0,
            firmware: "test",
            device_id: [7; 12],
            sample_rate_hz: 100,
            run: 12,
        };
        let mut bytes = vec![0x5a; garbage];
        let mut encoder = BlockEncoder::new();
        let frames = (0..frames).map(|i| {
            Record::Frame(Frame {
                t_us: i * 10_000,
                accel: [0; 3],
                gyro: [0; 3],
                steer_cdeg: (i % 100) as i16,
                wheel_count: 0,
                wheel_edge_age_us: EDGE_AGE_NONE,
                speed_mm_s: 4000,
                status: Default::default(),
            })
        });
        for rec in header_records(info, lines.iter().map(String::as_str)).chain(frames) {
            if let Some(block) = encoder.push(&rec).unwrap() {
                bytes.extend_from_slice(block);
            }
        }
        bytes.extend_from_slice(encoder.finish().unwrap());
        let file = tempfile::NamedTempFile::new().unwrap();
        std::fs::write(file.path(), &bytes).unwrap();
        (file, lines)
    }

    #[test]
    fn chunks_grow_from_any_first_length_and_cover_the_file() {
        let (file, _) = log(60_000, 700);
        let len = std::fs::metadata(file.path()).unwrap().len();
        // Records passed on, and bytes reported skipped.
        let count = |(records, skipped): &mut (u64, u64), event: Event<'_>| match event {
            Event::Record(_) => *records += 1,
            Event::Skipped { len, .. } => *skipped += len,
            _ => {}
        };
        let mut all = (0, 0);
        let whole = read_log(file.path(), |e| count(&mut all, e)).unwrap();
        assert_eq!(all, (whole.records, 700));
        for first_len in [0, 1, 513, BLOCK_LEN * 3 + 7, 1 << 30] {
            let mut seen = (0, 0);
            let stats = read_log_until(file.path(), first_len, |e| {
                count(&mut seen, e);
                ControlFlow::Continue(())
            })
            .unwrap();
            assert_eq!(stats, whole, "first chunk {first_len}");
            assert_eq!(stats.blocks * BLOCK_LEN as u64 + 700, len);
            assert_eq!(seen, all, "first chunk {first_len}");
        }
    }

    /// The frame times and the first record's kind of the log at `path`.
    fn frames_of(path: &Path) -> (Vec<u64>, bool, DecodeStats) {
        let mut times = Vec::new();
        let mut first_is_info = None;
        let stats = read_log(path, |e| {
            if let Event::Record(r) = e {
                first_is_info.get_or_insert(matches!(r, Record::LogInfo(_)));
                if let Record::Frame(f) = r {
                    times.push(f.t_us);
                }
            }
        })
        .unwrap();
        (times, first_is_info.unwrap_or(false), stats)
    }

    /// The log of [`log`] with its blocks put in the order `order` gives.
    fn reordered(frames: u64, order: impl Fn(usize) -> Vec<usize>) -> tempfile::NamedTempFile {
        let (file, _) = log(frames, 0);
        let bytes = std::fs::read(file.path()).unwrap();
        let blocks: Vec<&[u8]> = bytes.chunks(BLOCK_LEN).collect();
        let out: Vec<u8> = order(blocks.len())
            .into_iter()
            .flat_map(|i| blocks[i].iter().copied())
            .collect();
        std::fs::write(file.path(), out).unwrap();
        file
    }

    /// The block order of a case, given the number of blocks.
    type Order = dyn Fn(usize) -> Vec<usize>;

    #[test]
    fn reordered_and_copied_blocks_are_decoded_once_in_time_order() {
        let all: Vec<u64> = (0..3000).map(|i| i * 10_000).collect();
        let (clean, _) = log(3000, 0);
        let (_, _, whole) = frames_of(clean.path());
        let cases: [(&str, Box<Order>); 4] = [
            (
                "neighbours swapped",
                Box::new(|n| (0..n).map(|i| i ^ 1).map(|i| i.min(n - 1)).collect()),
            ),
            ("reversed", Box::new(|n| (0..n).rev().collect())),
            (
                "block 3 in front",
                Box::new(|n| std::iter::once(3).chain(0..n).collect()),
            ),
            (
                "every block twice",
                Box::new(|n| (0..n).chain(0..n).collect()),
            ),
        ];
        for (what, order) in cases {
            let file = reordered(3000, order);
            let (times, info_first, stats) = frames_of(file.path());
            assert_eq!(times, all, "{what}");
            assert!(info_first, "{what}: the header comes first");
            assert_eq!((stats.blocks, stats.frames), (whole.blocks, 3000), "{what}");
            assert_eq!(
                stats.blocks_lost + stats.frames_lost,
                0,
                "{what}: nothing lost"
            );
            assert_eq!(stats.time_jumps + stats.forward_time_jumps, 0, "{what}");
        }
    }

    #[test]
    fn copies_are_reported_as_one_skipped_stretch_each() {
        let file = reordered(3000, |n| (0..n).chain([4, 5, 6]).collect());
        let mut skips = Vec::new();
        let stats = read_log(file.path(), |e| {
            if let Event::Skipped { offset, len, cause } = e {
                skips.push((offset, len, cause));
            }
        })
        .unwrap();
        let n = stats.blocks;
        let at = n * BLOCK_LEN as u64;
        // Sorted by number, the copies sit next to their originals: one
        // report each, at the copy's place in the file.
        assert_eq!(
            skips,
            [4, 5, 6].map(|k| (
                at + (k - 4) * BLOCK_LEN as u64,
                BLOCK_LEN as u64,
                SkipCause::Repeated
            ))
        );
        assert_eq!(
            (stats.repeated_blocks, stats.bytes_skipped),
            (3, 3 * BLOCK_LEN as u64)
        );
    }

    #[test]
    fn a_break_ends_the_reading_and_the_events() {
        let (file, _) = log(60_000, 0);
        let mut events = 0;
        let stats = read_log_until(file.path(), 2 * BLOCK_LEN, |_| {
            events += 1;
            ControlFlow::Break(())
        })
        .unwrap();
        assert_eq!(events, 1);
        assert_eq!(stats.blocks, 2);
    }

    /// Every event of the log at `path` (as text), its totals, and how
    /// often the one-pass reader started again.
    fn restarting(path: &Path) -> (Vec<String>, DecodeStats, u32) {
        let events = std::cell::RefCell::new(Vec::new());
        let mut restarts = 0;
        let stats = read_log_restarting(
            path,
            |e| {
                events.borrow_mut().push(format!("{e:?}"));
                ControlFlow::Continue(())
            },
            || {
                restarts += 1;
                events.borrow_mut().clear();
            },
        )
        .unwrap();
        (events.into_inner(), stats, restarts)
    }

    #[test]
    fn one_pass_gives_the_events_of_two_and_starts_again_only_for_blocks_out_of_order() {
        let (in_order, _) = log(3000, 700);
        let swapped = reordered(3000, |n| {
            (0..n).map(|i| i ^ 1).map(|i| i.min(n - 1)).collect()
        });
        let copied = reordered(3000, |n| (0..n).chain([4, 5]).collect());
        for (what, path, restarts) in [
            ("in order", in_order.path(), 0),
            ("neighbours swapped", swapped.path(), 1),
            ("copies at the end", copied.path(), 1),
        ] {
            let mut expected = Vec::new();
            let stats = read_log(path, |e| expected.push(format!("{e:?}"))).unwrap();
            assert_eq!(restarting(path), (expected, stats, restarts), "{what}");
        }
        // A visitor that stops is not made to start again.
        let mut restarted = false;
        read_log_restarting(
            swapped.path(),
            |_| ControlFlow::Break(()),
            || restarted = true,
        )
        .unwrap();
        assert!(!restarted);
        // No valid block: the usual error.
        let empty = tempfile::NamedTempFile::new().unwrap();
        let e = read_log_restarting(empty.path(), |_| ControlFlow::Continue(()), || {});
        assert!(e.unwrap_err().to_string().contains("empty file"));
    }
}
