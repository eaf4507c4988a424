//! The GPS task: UART bytes through the core's GPS path into records.
//!
//! On the board ([`run_link`]) the task also keeps the receiver: it runs
//! the bring-up ([`super::gps_setup`]), logs at the baud it ended with,
//! and when no valid sentence has come for [`LOSS_TIMEOUT_US`] (a receiver
//! that browned out or was re-plugged comes back at its stored baud, and
//! every byte is then a framing error) records the loss and runs the
//! bring-up again. The QEMU image replays a capture through [`run`].

use embassy_futures::select::{select, Either};
use embassy_time::{Instant, Timer};

use super::gps_setup::{self, GpsLink};
use super::ports::GpsPort;
use crate::channels::{RecordQueue, SharedStatus};
use crate::drivers::gnss_bringup::{Step, FAULT_RECEIVER_LOST};
use crate::format::{Fault, FaultSource, Record};
use crate::gps::{GpsConfig, GpsEvent, GpsReceiver};

/// No valid sentence for this long while logging: the receiver is taken as
/// lost and brought up again. Even an unconfigured 1 Hz receiver sends a
/// few valid lines a second; 3 s rides out a burst of line noise.
pub const LOSS_TIMEOUT_US: u64 = 3_000_000;

/// Why [`run_until`] returned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ended {
    /// [`SharedStatus::request_stop`].
    Stopped,
    /// No valid sentence for the loss timeout.
    Lost,
}

/// Longest wait for bytes before the receiver is polled anyway, so an epoch
/// whose last sentence never comes is still emitted on its timeout.
pub const IDLE_POLL_MS: u64 = 100;

/// Reads the GPS until [`SharedStatus::request_stop`]. The port's `read`
/// must be cancel-safe (bytes it has not returned stay buffered), since a
/// read is abandoned when the poll timer wins.
pub async fn run<G: GpsPort>(
    port: &mut G,
    receiver: &mut GpsReceiver,
    queue: &RecordQueue,
    shared: &SharedStatus,
) {
    run_until(port, receiver, queue, shared, None).await;
}

/// The board's GPS task: brings the receiver up, logs at the baud the
/// bring-up ended with (the receiver's byte times are back-dated at that
/// baud), and brings it up again whenever it is lost (module docs), until
/// [`SharedStatus::request_stop`]. `on_step` sees each bring-up step.
/// Each bring-up's fault (silent, unconfirmed, slow) and each loss
/// ([`FAULT_RECEIVER_LOST`]) is queued as a GPS fault record.
pub async fn run_link<L: GpsLink>(
    link: &mut L,
    queue: &RecordQueue,
    shared: &SharedStatus,
    on_step: &mut impl FnMut(&Step),
) {
    while !shared.stop_requested() {
        let outcome = gps_setup::run(link, on_step).await;
        if let Some(code) = outcome.fault() {
            queue.push(gps_fault(code));
        }
        let mut receiver = GpsReceiver::new(GpsConfig {
            baud: outcome.baud,
            ..GpsConfig::default()
        });
        let ended = run_until(link, &mut receiver, queue, shared, Some(LOSS_TIMEOUT_US)).await;
        // What the receiver still holds (an open epoch, fault counts
        // waiting for their interval) goes out before it is replaced.
        receiver.finish(Instant::now().as_micros(), &mut |ev| {
            queue.push(record(ev, shared));
        });
        if ended == Ended::Lost {
            queue.push(gps_fault(FAULT_RECEIVER_LOST));
        }
    }
}

fn gps_fault(code: u8) -> Record<'static> {
    Record::Fault(Fault {
        t_us: Instant::now().as_micros(),
        source: FaultSource::Gps,
        code,
        count: 1,
    })
}

/// The record for `ev`; a fix with a position also refreshes the fix age.
fn record(ev: GpsEvent, shared: &SharedStatus) -> Record<'static> {
    match ev {
        GpsEvent::Fix(fix) => {
            if fix.lat_e7.is_some() {
                shared.set_fix(fix.t_us);
            }
            Record::Gps(fix)
        }
        GpsEvent::UtcSync(sync) => {
            shared.set_utc(sync);
            Record::UtcSync(sync)
        }
        GpsEvent::Fault(fault) => Record::Fault(fault),
    }
}

/// Feeds `receiver` from `port` until a stop is requested or, with
/// `lost_after_us`, until no valid sentence has come for that long (timed
/// from the start, so a receiver that never talks is lost too).
async fn run_until<G: GpsPort>(
    port: &mut G,
    receiver: &mut GpsReceiver,
    queue: &RecordQueue,
    shared: &SharedStatus,
    lost_after_us: Option<u64>,
) -> Ended {
    let mut buf = [0u8; 64];
    let mut emit = |ev: GpsEvent| {
        queue.push(record(ev, shared));
    };
    let mut lines = receiver.stats().lines;
    let mut last_valid_us = Instant::now().as_micros();
    while !shared.stop_requested() {
        let read = select(port.read(&mut buf), Timer::after_millis(IDLE_POLL_MS)).await;
        let now_us = Instant::now().as_micros();
        match read {
            Either::First(n) if n > 0 => {
                // Bytes that came after this chunk wait in the port.
                let t_last_us = now_us.saturating_sub(receiver.chars_us(port.pending()));
                receiver.feed(buf.get(..n).unwrap_or(&buf), t_last_us, &mut emit);
            }
            Either::First(_) => {
                // The replayed capture ended: nothing more will come.
                Timer::after_millis(IDLE_POLL_MS).await;
                receiver.poll(now_us, &mut emit);
            }
            Either::Second(()) => receiver.poll(now_us, &mut emit),
        }
        let heard = receiver.stats().lines;
        if heard != lines {
            lines = heard;
            last_valid_us = now_us;
        }
        if lost_after_us.is_some_and(|after| now_us.saturating_sub(last_valid_us) >= after) {
            return Ended::Lost;
        }
    }
    Ended::Stopped
}
