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
