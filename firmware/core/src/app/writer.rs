//! The SD writer task: drains the record queue into the card logger, in
//! thread mode, where embedded-sdmmc's blocking writes may take as long as
//! the card likes while the sampler preempts it.
//!
//! While the supply is below the power-fail threshold
//! ([`SharedStatus::power_low`]) the writer closes the file and touches the
//! card no more until it is back.
//!
//! One iteration is a [`CardLogger::poll`] (a flush when one is due, an
//! attempt to open a card without one), with no record waiting a block of
//! zeros ahead of the data ([`CardLogger::write_ahead`]), and the push of
//! one record (which writes a block when it closes one). The card
//! operations of each iteration and its busy time are counted ([`SharedStatus::writer`]): the
//! queue is sized for the worst iteration (`channels`), and the figures
//! show how close a card came to it.

use embassy_futures::select::{select, Either};
use embassy_time::{Instant, Timer};
use embedded_sdmmc::{BlockDevice, TimeSource};

use crate::channels::{RecordQueue, SharedStatus};
use crate::logger::{CardLogger, CloseError, LoggerState};

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
    // How the last file closed for a failing supply went.
    let mut power_closed = Err(CloseError::NoFile);
    loop {
        if shared.power_low() {
            // The supply is failing: the file closed now, while the card
            // still has the voltage to take a few writes (the queue waits,
            // and drops what does not fit, counted), and no card access
            // until the supply is back, which opens a new file.
            if matches!(logger.state(), LoggerState::Logging { .. }) {
                power_closed = logger.close(Instant::now().as_micros());
                shared.set_card(logger.state().into());
            }
            if shared.stop_requested() {
                return power_closed;
            }
            Timer::after_millis(IDLE_POLL_MS).await;
            continue;
        }
        let logging = matches!(logger.state(), LoggerState::Logging { .. });
        let ops_before = logger.card_ops();
        // Polled before the first record too: the card is opened at boot,
        // while the queue holds what the sampler makes meanwhile.
        let start = Instant::now().as_micros();
        logger.poll(start);
        if queue.is_empty() {
            // Nothing waiting: a block of zeros ahead of the data.
            logger.write_ahead(start);
        }
        let mut busy_us = Instant::now().as_micros().saturating_sub(start);
        shared.set_card(logger.state().into());
        let next = select(queue.pop(), Timer::after_millis(IDLE_POLL_MS)).await;
        if let Either::First(rec) = next {
            let start = Instant::now().as_micros();
            logger.push(&rec, start);
            busy_us += Instant::now().as_micros().saturating_sub(start);
        }
        let ops = logger.card_ops().since(ops_before).total();
        // An iteration that opened the card (or tried to) is not one of
        // the ride's: it is counted apart (`SharedStatus::writer`).
        shared.note_writer_iteration(logging, ops, busy_us);
        if shared.stop_requested() && queue.is_empty() {
            return logger.close(Instant::now().as_micros());
        }
    }
}
