//! The GPS task: UART bytes through the core's GPS path into records.

use embassy_futures::select::{select, Either};
use embassy_time::{Instant, Timer};

use super::ports::GpsPort;
use crate::channels::{RecordQueue, SharedStatus};
use crate::format::Record;
use crate::gps::{GpsEvent, GpsReceiver};

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
    let mut buf = [0u8; 64];
    let mut emit = |ev: GpsEvent| {
        let rec = match ev {
            GpsEvent::Fix(fix) => {
                if fix.lat_e7.is_some() {
                    shared.set_fix(fix.t_us);
                }
                Record::Gps(fix)
            }
            GpsEvent::UtcSync(sync) => Record::UtcSync(sync),
            GpsEvent::Fault(fault) => Record::Fault(fault),
        };
        queue.push(rec);
    };
    while !shared.stop_requested() {
        let read = select(port.read(&mut buf), Timer::after_millis(IDLE_POLL_MS)).await;
        let now_us = Instant::now().as_micros();
        match read {
            Either::First(n) if n > 0 => receiver.feed(&buf[..n], now_us, &mut emit),
            Either::First(_) => {
                // The replayed capture ended: nothing more will come.
                Timer::after_millis(IDLE_POLL_MS).await;
                receiver.poll(now_us, &mut emit);
            }
            Either::Second(()) => receiver.poll(now_us, &mut emit),
        }
    }
}
