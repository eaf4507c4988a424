//! The SD writer task: drains the record queue into the card logger, in
//! thread mode, where embedded-sdmmc's blocking writes may take as long as
//! the card likes while the sampler preempts it.

use embassy_futures::select::{select, Either};
use embassy_time::{Instant, Timer};
use embedded_sdmmc::{BlockDevice, TimeSource};

use crate::channels::{RecordQueue, SharedStatus};
use crate::logger::{CardLogger, CloseError};

/// Longest wait for a record before the logger is polled anyway (flushes
/// and card retries happen even if the producers go quiet).
pub const IDLE_POLL_MS: u64 = 50;

/// Writes queued records until [`SharedStatus::request_stop`], then writes
/// what is left, closes the file and returns how the close went.
///
/// # Errors
/// The file could not be closed cleanly (no card, or the card failed); the
/// card then holds the state of the last flush.
pub async fn run<D: BlockDevice, T: TimeSource>(
    logger: &mut CardLogger<'_, D, T>,
    queue: &RecordQueue,
    shared: &SharedStatus,
) -> Result<(), CloseError> {
    loop {
        // Polled before the first record too: the card is opened at boot,
        // while the queue holds what the sampler makes meanwhile.
        logger.poll(Instant::now().as_micros());
        shared.set_card(logger.state().into());
        let next = select(queue.pop(), Timer::after_millis(IDLE_POLL_MS)).await;
        if let Either::First(rec) = next {
            logger.push(&rec, Instant::now().as_micros());
        }
        if shared.stop_requested() && queue.is_empty() {
            return logger.close(Instant::now().as_micros());
        }
    }
}
