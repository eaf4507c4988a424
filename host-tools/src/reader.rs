//! Reading a card log from a file, in bounded memory, with progress.

use std::fs::File;
use std::io::Read;
use std::ops::ControlFlow;
use std::path::Path;

use indicatif::{ProgressBar, ProgressStyle};
use wobble_core::format::{DecodeStats, Decoder, Event, BLOCK_LEN};

use crate::CliError;

/// Bytes read from the file at a time.
const CHUNK_LEN: usize = 1 << 20;
/// Files larger than this get a progress bar (when stderr is a terminal).
const PROGRESS_MIN_LEN: u64 = 64 << 20;

/// Decodes the log at `path`, calling `visit` for every event in file order.
///
/// Memory use is bounded by the chunk size whatever the file holds. A file
/// in which not a single valid block is found is an error: it is not a card
/// log, or nothing of it survived.
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
    let mut file = File::open(path).map_err(|e| CliError::file(path, e))?;
    let len = file.metadata().map_err(|e| CliError::file(path, e))?.len();
    let progress = progress_bar(len);
    let mut decoder = Decoder::new();
    let mut buf = vec![0u8; CHUNK_LEN];
    let mut filled = 0;
    // The decoder leaves less than a block unconsumed: two blocks always
    // make progress.
    let mut limit = first_len.clamp(2 * BLOCK_LEN, CHUNK_LEN);
    let mut stopped = false;
    loop {
        let read = fill(&mut file, &mut buf[filled..limit]).map_err(|e| CliError::file(path, e))?;
        filled += read;
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
    let stats = *decoder.stats();
    if stats.blocks == 0 {
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

fn progress_bar(len: u64) -> ProgressBar {
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
    bar.set_message("decoding");
    bar
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use wobble_core::config::Config;
    use wobble_core::format::header::header_records;
    use wobble_core::format::{BlockEncoder, Frame, LogInfo, Record, EDGE_AGE_NONE};

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
}
