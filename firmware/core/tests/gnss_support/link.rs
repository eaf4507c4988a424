//! A UART wired to a simulated [`Receiver`], in virtual time (the mock
//! time driver): each byte arrives when its stop bit ends, at the line's
//! pace, and a read wakes as embassy's ring-buffered UART does, when the
//! line goes idle (one character time) or half the ring has filled, returning what fits the
//! caller's buffer (the rest stays pending). A baud switch loses what was
//! on the line; commands take their time on the wire.

use std::collections::VecDeque;
use std::future::Future;
use std::pin::pin;
use std::sync::{Mutex, MutexGuard};
use std::task::{Context, Poll, Waker};

use embassy_time::{Duration, Instant, MockDriver, Timer};
use wobble_core::app::gps_setup::GpsLink;
use wobble_core::app::ports::GpsPort;

use super::Receiver;

/// The mock time driver is one global clock: one test at a time.
static CLOCK: Mutex<()> = Mutex::new(());

/// Bytes on the line are generated a window at a time.
pub const WINDOW_US: u64 = 1_000_000;
/// Half the board's DMA ring: a read wakes at the latest when this many
/// bytes wait.
const HALF_RING: usize = 512;

/// A UART wired to a simulated receiver.
pub struct SimLink {
    pub rx: Receiver,
    pub baud: u32,
    /// Bytes generated and not yet read, each with the time it arrives.
    line: VecDeque<(Instant, u8)>,
    /// When the current window began.
    window_start: Instant,
    /// Every baud switch and every command sent, with the baud it went at.
    pub switches: Vec<u32>,
    pub sent: Vec<(u32, Vec<u8>)>,
    /// The longest time between two reads started (the heartbeat).
    last_read: Option<Instant>,
    pub max_read_gap: Duration,
    /// At this time the receiver is replaced by this one (a brown-out or a
    /// re-plug: back in its power-up state).
    pub reset: Option<(Instant, Receiver)>,
    /// Bytes that had arrived but did not fit the last read's buffer.
    left: usize,
    /// When each `$` read from the line had arrived (the true start of
    /// each sentence, for checking the fixes' timestamps).
    pub dollars: Vec<Instant>,
}

impl SimLink {
    pub fn new(rx: Receiver) -> Self {
        Self {
            rx,
            baud: 9_600,
            line: VecDeque::new(),
            window_start: Instant::now(),
            switches: Vec::new(),
            sent: Vec::new(),
            last_read: None,
            max_read_gap: Duration::from_ticks(0),
            reset: None,
            left: 0,
            dollars: Vec::new(),
        }
    }

    fn start_window(&mut self, at: Instant) {
        if let Some((when, _)) = self.reset {
            if at >= when {
                self.rx = self
                    .reset
                    .take()
                    .map(|(_, rx)| rx)
                    .unwrap_or_else(|| unreachable!());
            }
        }
        self.window_start = at;
        let bytes = self.rx.transmit_timed(self.baud, WINDOW_US);
        self.line.extend(
            bytes
                .into_iter()
                .map(|(t, b)| (at + Duration::from_micros(t), b)),
        );
    }

    /// Generates the windows that have begun by now.
    fn catch_up(&mut self) {
        let window = Duration::from_micros(WINDOW_US);
        while Instant::now() >= self.window_start + window {
            self.start_window(self.window_start + window);
        }
    }

    /// Bytes that have arrived by now.
    fn arrived(&mut self) -> usize {
        self.catch_up();
        let now = Instant::now();
        self.line.iter().take_while(|(t, _)| *t <= now).count()
    }

    /// Whether a waiting read wakes on the `arrived` bytes: the line has
    /// been idle for a character time since the last (the UART's IDLE
    /// flag), or half a ring waits.
    fn wakes(&self, arrived: usize) -> bool {
        let idle = Duration::from_micros(10_000_000 / u64::from(self.baud));
        match arrived.checked_sub(1).and_then(|i| self.line.get(i)) {
            None => false,
            Some(&(last, _)) => arrived >= HALF_RING || Instant::now() >= last + idle,
        }
    }
}

impl GpsPort for SimLink {
    async fn read(&mut self, buf: &mut [u8]) -> usize {
        let now = Instant::now();
        if let Some(last) = self.last_read {
            self.max_read_gap = self.max_read_gap.max(now.duration_since(last));
        }
        self.last_read = Some(now);
        // What has arrived when the read starts is returned at once;
        // otherwise the read waits for the UART's wake-up.
        let mut first = true;
        loop {
            let arrived = self.arrived();
            if arrived > 0 && (first || self.wakes(arrived)) {
                let n = arrived.min(buf.len());
                for (slot, (t, b)) in buf.iter_mut().zip(self.line.drain(..n)) {
                    *slot = b;
                    if b == b'$' {
                        self.dollars.push(t);
                    }
                }
                self.left = arrived - n;
                return n;
            }
            first = false;
            Timer::after_micros(500).await;
        }
    }

    fn pending(&self) -> usize {
        self.left
    }
}

impl GpsLink for SimLink {
    fn set_baud(&mut self, baud: u32) {
        self.switches.push(baud);
        self.baud = baud;
        // What was on the line at the old baud is lost.
        self.line.clear();
        self.left = 0;
        self.start_window(Instant::now());
    }

    async fn send(&mut self, bytes: &[u8]) {
        // 10 bits a byte on the wire.
        let us = bytes.len() as u64 * 10 * 1_000_000 / u64::from(self.baud);
        Timer::after_micros(us).await;
        self.rx.receive(self.baud, bytes);
        self.sent.push((self.baud, bytes.to_vec()));
    }
}

/// A fresh clock (held until the guard drops) and a link to `rx`.
pub fn link_to(rx: Receiver) -> (MutexGuard<'static, ()>, SimLink) {
    let guard = CLOCK
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    MockDriver::get().reset();
    (guard, SimLink::new(rx))
}

/// Polls `future` to its end in virtual time, 1 ms a step, calling `each_ms`
/// between steps; panics after `limit`.
pub fn drive<F: Future>(future: F, limit: Duration, each_ms: &mut impl FnMut()) -> F::Output {
    let start = Instant::now();
    let mut future = pin!(future);
    let mut cx = Context::from_waker(Waker::noop());
    let driver = MockDriver::get();
    loop {
        if let Poll::Ready(out) = future.as_mut().poll(&mut cx) {
            return out;
        }
        assert!(
            Instant::now().duration_since(start) < limit,
            "did not end within {limit}"
        );
        each_ms();
        driver.advance(Duration::from_millis(1));
    }
}
