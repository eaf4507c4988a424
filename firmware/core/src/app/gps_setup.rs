//! Drives the GPS bring-up ([`crate::drivers::gnss_bringup`]) over the
//! board's UART: switches the baud rate, sends the commands, listens.
//! Runs at the start of the GPS task and again whenever the receiver is
//! lost (`app::gps::run_link`); everything it decides is the state
//! machine's.

use embassy_futures::select::{select, Either};
use embassy_time::{Duration, Instant, Timer};

use super::gps::IDLE_POLL_MS;
use super::ports::GpsPort;
use crate::drivers::gnss_bringup::{Bringup, Outcome, SentenceCounter, Step, SETTLE_US};

/// The GPS UART, both directions.
#[allow(async_fn_in_trait)]
pub trait GpsLink: GpsPort {
    /// Switches the UART (receive and transmit) to `baud`.
    fn set_baud(&mut self, baud: u32);
    /// Sends `bytes` and waits until they have left.
    async fn send(&mut self, bytes: &[u8]);
}

/// Reads from `link` until `until`, handing each chunk to `chunk`. A read
/// is started at least every [`IDLE_POLL_MS`], as in the GPS task, so the
/// port's liveness heartbeat goes on while the line is silent.
async fn read_until<L: GpsLink>(link: &mut L, until: Instant, chunk: &mut impl FnMut(&[u8])) {
    let mut buf = [0u8; 64];
    while Instant::now() < until {
        let poll = (Instant::now() + Duration::from_millis(IDLE_POLL_MS)).min(until);
        match select(link.read(&mut buf), Timer::at(poll)).await {
            Either::First(n) if n > 0 => chunk(buf.get(..n).unwrap_or_default()),
            // A replayed capture ended, or nothing came: wait and ask again.
            Either::First(_) => Timer::at(poll).await,
            Either::Second(()) => {}
        }
    }
}

/// Runs the bring-up to its end and returns how it ended; `on_step` sees
/// each step before it is taken (one log line each, a few dozen at most).
pub async fn run<L: GpsLink>(link: &mut L, on_step: &mut impl FnMut(&Step)) -> Outcome {
    let mut setup = Bringup::new();
    let mut step = setup.step();
    loop {
        on_step(&step);
        step = match step {
            Step::Listen { baud, for_us } => {
                link.set_baud(baud);
                // What the ring holds came at the old baud, and the first
                // sentence may be cut: skip a settling time first.
                let settled = Instant::now() + Duration::from_micros(SETTLE_US);
                read_until(link, settled, &mut |_| {}).await;
                let mut counter = SentenceCounter::new();
                let end = Instant::now() + Duration::from_micros(for_us);
                read_until(link, end, &mut |bytes| counter.feed(bytes)).await;
                setup.heard(counter.heard())
            }
            Step::Send { baud, set } => {
                link.set_baud(baud);
                for cmd in set.commands() {
                    link.send(&cmd).await;
                }
                Timer::after_micros(SETTLE_US).await;
                setup.sent()
            }
            Step::Done(outcome) => {
                // The last step may have listened at another baud (a
                // silent probe ends at 115 200): log at the outcome's.
                link.set_baud(outcome.baud);
                return outcome;
            }
        };
    }
}
