//! The async GPS bring-up runner (`app::gps_setup::run`) over a simulated
//! UART in virtual time: the receiver's bytes arrive at the line's pace, a
//! baud switch loses what was in flight, commands take their time on the
//! wire. The state machine's decisions are tested in `gnss_bringup.rs`;
//! here, that the runner carries them out on a link: baud switches before
//! each step, commands sent whole and in order, the settling time skipped,
//! the port read at least every `IDLE_POLL_MS` while listening and well
//! within a watchdog round while sending (the GPS task's heartbeat),
//! and the whole bring-up bounded in time and in log lines.

mod gnss_support;

use std::future::Future;
use std::pin::pin;
use std::sync::Mutex;
use std::task::{Context, Poll, Waker};

use embassy_time::{Duration, Instant, MockDriver, Timer};
use gnss_support::{Family, Receiver};
use wobble_core::app::gps::IDLE_POLL_MS;
use wobble_core::app::gps_setup::{run, GpsLink};
use wobble_core::app::ports::GpsPort;
use wobble_core::drivers::gnss_bringup::{
    CommandSet, Outcome, Step, FAULT_SETUP_SILENT, FAULT_SETUP_UNCONFIRMED, SETTLE_US,
};
use wobble_core::drivers::gnss_setup::TARGET_BAUD;
use wobble_core::watchdog::ROUND_US;

/// The mock time driver is one global clock: one test at a time.
static CLOCK: Mutex<()> = Mutex::new(());

/// Bytes on the line are generated a window at a time and released at the
/// line's pace.
const WINDOW_US: u64 = 1_000_000;

/// A UART wired to a simulated receiver.
struct SimLink {
    rx: Receiver,
    baud: u32,
    /// The bytes of the current window, when it started, and how many of
    /// them have been handed out.
    window: Vec<u8>,
    window_start: Instant,
    taken: usize,
    /// Every baud switch and every command sent, with the baud it went at.
    switches: Vec<u32>,
    sent: Vec<(u32, Vec<u8>)>,
    /// The longest time between two reads started (the heartbeat).
    last_read: Option<Instant>,
    max_read_gap: Duration,
}

impl SimLink {
    fn new(rx: Receiver) -> Self {
        Self {
            rx,
            baud: 9_600,
            window: Vec::new(),
            window_start: Instant::now(),
            taken: 0,
            switches: Vec::new(),
            sent: Vec::new(),
            last_read: None,
            max_read_gap: Duration::from_ticks(0),
        }
    }

    fn start_window(&mut self) {
        self.window = self.rx.transmit(self.baud, WINDOW_US);
        self.window_start = Instant::now();
        self.taken = 0;
    }

    /// Bytes of the window that have arrived by now and not been read.
    fn arrived(&mut self) -> usize {
        let elapsed = Instant::now().duration_since(self.window_start).as_micros();
        if elapsed >= WINDOW_US && self.taken == self.window.len() {
            self.start_window();
            return 0;
        }
        let due = (self.window.len() as u64 * elapsed.min(WINDOW_US) / WINDOW_US) as usize;
        due - self.taken
    }
}

impl GpsPort for SimLink {
    async fn read(&mut self, buf: &mut [u8]) -> usize {
        let now = Instant::now();
        if let Some(last) = self.last_read {
            self.max_read_gap = self.max_read_gap.max(now.duration_since(last));
        }
        self.last_read = Some(now);
        loop {
            let n = self.arrived().min(buf.len());
            if n > 0 {
                buf[..n].copy_from_slice(&self.window[self.taken..self.taken + n]);
                self.taken += n;
                return n;
            }
            // A real UART wakes on its idle-line interrupt; 5 ms is finer
            // than any listening window.
            Timer::after_millis(5).await;
        }
    }
}

impl GpsLink for SimLink {
    fn set_baud(&mut self, baud: u32) {
        self.switches.push(baud);
        self.baud = baud;
        // What was on the line at the old baud is lost.
        self.start_window();
    }

    async fn send(&mut self, bytes: &[u8]) {
        // 10 bits a byte on the wire.
        let us = bytes.len() as u64 * 10 * 1_000_000 / u64::from(self.baud);
        Timer::after_micros(us).await;
        self.rx.receive(self.baud, bytes);
        self.sent.push((self.baud, bytes.to_vec()));
    }
}

/// Runs the bring-up on `link` to its end in virtual time (1 ms steps);
/// returns the outcome, the steps logged and the time taken.
fn bring_up(link: &mut SimLink) -> (Outcome, Vec<Step>, Duration) {
    let mut steps = Vec::new();
    let start = Instant::now();
    let outcome = {
        let mut log = |step: &Step| steps.push(*step);
        let mut future = pin!(run(link, &mut log));
        let mut cx = Context::from_waker(Waker::noop());
        let driver = MockDriver::get();
        loop {
            if let Poll::Ready(outcome) = future.as_mut().poll(&mut cx) {
                break outcome;
            }
            assert!(
                Instant::now().duration_since(start) < Duration::from_secs(120),
                "bring-up did not end"
            );
            driver.advance(Duration::from_millis(1));
        }
    };
    (outcome, steps, Instant::now().duration_since(start))
}

/// A fresh clock and a link to `rx`.
fn link_to(rx: Receiver) -> (std::sync::MutexGuard<'static, ()>, SimLink) {
    let guard = CLOCK
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    MockDriver::get().reset();
    (guard, SimLink::new(rx))
}

/// The baud each Listen or Send step asked for, in order.
fn asked_bauds(steps: &[Step]) -> Vec<u32> {
    steps
        .iter()
        .filter_map(|step| match *step {
            Step::Listen { baud, .. } | Step::Send { baud, .. } => Some(baud),
            Step::Done(_) => None,
        })
        .collect()
}

#[test]
fn a_mediatek_at_9600_is_brought_to_115200_at_20_hz_on_the_link() {
    let (_clock, mut link) = link_to(Receiver::new(Family::Mtk, 9_600));
    let (outcome, steps, took) = bring_up(&mut link);
    assert_eq!(outcome.found_baud, Some(9_600));
    assert_eq!(outcome.configured, Some(CommandSet::LegacyRate));
    assert_eq!((outcome.baud, outcome.rate_hz), (TARGET_BAUD, 20));
    assert_eq!(outcome.fault(), None);
    assert_eq!(
        (link.rx.baud, link.rx.rate_hz, link.rx.lean),
        (TARGET_BAUD, 20, true)
    );
    // The UART is switched before every step, to the step's baud.
    assert_eq!(link.switches, asked_bauds(&steps));
    assert_eq!(steps.last(), Some(&Step::Done(outcome)));
    // Each set went out whole, in order, at the baud its step named.
    let mut expected = Vec::new();
    for step in &steps {
        if let Step::Send { baud, set } = *step {
            expected.extend(set.commands().iter().map(|c| (baud, c.to_vec())));
        }
    }
    assert_eq!(link.sent, expected);
    assert!(took < Duration::from_secs(10), "took {took}");
    // Sending a set and settling is the longest time without a read (the
    // legacy baud set at 9600 plus the settling time: about 0.37 s); the
    // watchdog wants a heartbeat every round, well within that.
    assert!(
        link.max_read_gap < Duration::from_micros(ROUND_US / 2),
        "reads {} apart",
        link.max_read_gap
    );
}

#[test]
fn a_ublox_m10_at_38400_is_configured_with_valset_on_the_link() {
    let (_clock, mut link) = link_to(Receiver::new(Family::UbloxM10, 38_400));
    let (outcome, steps, _) = bring_up(&mut link);
    assert_eq!(outcome.found_baud, Some(38_400));
    assert_eq!(outcome.configured, Some(CommandSet::Valset));
    assert_eq!((outcome.baud, outcome.rate_hz), (TARGET_BAUD, 20));
    assert_eq!(link.switches, asked_bauds(&steps));
    // The legacy set went first and changed nothing: VALSET did it.
    let sets: Vec<_> = steps
        .iter()
        .filter_map(|s| match *s {
            Step::Send { set, .. } => Some(set),
            _ => None,
        })
        .collect();
    assert_eq!(sets.first(), Some(&CommandSet::LegacyBaud));
    assert_eq!(sets.last(), Some(&CommandSet::Valset));
}

#[test]
fn a_deaf_receiver_is_left_at_its_baud_after_a_bounded_bring_up() {
    let (_clock, mut link) = link_to(Receiver::new(Family::Deaf, 9_600));
    let (outcome, steps, took) = bring_up(&mut link);
    assert_eq!((outcome.baud, outcome.configured), (9_600, None));
    assert_eq!(outcome.fault(), Some(FAULT_SETUP_UNCONFIRMED));
    assert!(steps.len() < 40, "{} log lines", steps.len());
    assert!(took < Duration::from_secs(30), "took {took}");
}

#[test]
fn a_silent_line_ends_at_9600_with_reads_all_along() {
    let mut rx = Receiver::new(Family::Mtk, 9_600);
    rx.silent = true;
    let (_clock, mut link) = link_to(rx);
    let (outcome, steps, took) = bring_up(&mut link);
    assert_eq!((outcome.found_baud, outcome.baud), (None, 9_600));
    assert_eq!(outcome.fault(), Some(FAULT_SETUP_SILENT));
    // Listening plus settling per probe, nothing more.
    let listening: u64 = steps
        .iter()
        .map(|s| match *s {
            Step::Listen { for_us, .. } => for_us + SETTLE_US,
            _ => 0,
        })
        .sum();
    let slack = Duration::from_millis(steps.len() as u64 * 10);
    assert!(took >= Duration::from_micros(listening), "took {took}");
    assert!(
        took <= Duration::from_micros(listening) + slack,
        "took {took}"
    );
    // Nothing arrives, yet the port is read every poll period.
    assert!(link.max_read_gap <= Duration::from_millis(IDLE_POLL_MS));
}

#[test]
fn a_receiver_already_at_115200_is_found_after_garbage_at_the_lower_bauds() {
    // A receiver already configured: at 115 200 and 20 Hz from the start.
    let mut rx = Receiver::new(Family::UbloxM8, TARGET_BAUD);
    rx.rate_hz = 20;
    let (_clock, mut link) = link_to(rx);
    let (outcome, steps, _) = bring_up(&mut link);
    // Found at 115 200 only after the lower bauds heard garbage.
    assert_eq!(outcome.found_baud, Some(TARGET_BAUD));
    assert_eq!(outcome.rate_hz, 20);
    assert_eq!(
        &asked_bauds(&steps)[..4],
        &[9_600, 38_400, 57_600, TARGET_BAUD]
    );
}
