//! The wheel's hall sensor on TIM5 channel 1: the timer latches its 32-bit
//! count (1 µs per count) at each falling edge in hardware; the capture
//! interrupt reads the latched count, the running count and the clock, and
//! queues the three for the sampler, which turns them into edge times with
//! the core's [`EdgeClock`].
//!
//! Own interrupt handler, not embassy-stm32's input capture: its 0.6.0
//! future returns the capture through the 16-bit timer view (a 32-bit count
//! masked to 16 bits), and it rewrites the input filter to "none" on every
//! wait. Here the 32-bit CCR1 is read through the PAC and the filter stays.

use core::sync::atomic::{AtomicU32, Ordering};

use embassy_stm32::interrupt;
use embassy_stm32::interrupt::{InterruptExt, Priority};
use embassy_stm32::pac;
use embassy_stm32::peripherals::TIM5;
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::input_capture::CapturePin;
use embassy_stm32::timer::low_level::{
    CountingMode, FilterValue, InputCaptureMode, InputTISelection, Timer,
};
use embassy_stm32::timer::{Ch1, Channel as TimerChannel};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_time::Instant;
use wobble_core::app::ports::WheelPort;
use wobble_core::wheel_capture::{CaptureStats, EdgeClock, RawCapture};

use crate::pins::WheelPins;

/// Captures waiting for the sampler: at 240 edges/s a 10 ms frame sees
/// about 3; 32 cover a sampler 130 ms late (longer than an IMU
/// re-initialisation, 46 ms).
const EDGE_QUEUE_LEN: usize = 32;

/// One count per µs: the edge resolution, and the unit of the clock.
const TICK_HZ: u32 = 1_000_000;

/// Input filter: 8 samples at f_DTS / 32 = 84 MHz / 32 must agree, so a
/// pulse shorter than 3 µs (wiring noise) is no edge; each real edge is
/// delayed by the same 3 µs, which cancels in every interval.
const FILTER: FilterValue = FilterValue::FDTS_DIV32_N8;

/// Above the executors (P6, P7), below the DMA interrupts (P0): the capture
/// is latched in hardware, so only the queueing waits.
const IRQ_PRIORITY: Priority = Priority::P5;

/// Capture interrupt -> sampler.
static EDGES: Channel<CriticalSectionRawMutex, RawCapture, EDGE_QUEUE_LEN> = Channel::new();
/// Captures lost because the sampler did not drain the queue.
static EDGES_LOST: AtomicU32 = AtomicU32::new(0);

/// The timer and its pin, kept configured for as long as this lives
/// (dropping the timer would stop its clock).
pub struct WheelTimer {
    _timer: Timer<'static, TIM5>,
    _hall: CapturePin<'static, TIM5, Ch1>,
}

/// Configures TIM5 as a free-running 32-bit 1 MHz counter capturing
/// falling edges on PA0, and enables its interrupt.
pub fn start(pins: WheelPins) -> WheelTimer {
    // The sensor is open collector: the internal pull-up (about 40 kΩ)
    // holds the line high; see the pin table for the external one.
    let hall = CapturePin::new(pins.hall, embassy_stm32::gpio::Pull::Up);
    let mut timer = Timer::new(pins.timer);
    timer.set_counting_mode(CountingMode::EdgeAlignedUp);
    timer.set_tick_freq(Hertz(TICK_HZ));
    // The whole 32-bit range, explicitly: the age arithmetic wraps at 2^32.
    timer.set_max_compare_value(u32::MAX);
    let ch = TimerChannel::Ch1;
    timer.set_input_ti_selection(ch, InputTISelection::Normal);
    timer.set_input_capture_filter(ch, FILTER);
    timer.set_input_capture_mode(ch, InputCaptureMode::Falling);
    timer.set_input_capture_prescaler(ch, 0);
    timer.enable_channel(ch, true);
    timer.clear_input_interrupt(ch);
    timer.enable_input_interrupt(ch, true);
    timer.start();
    interrupt::TIM5.set_priority(IRQ_PRIORITY);
    interrupt::TIM5.unpend();
    // SAFETY: the handler below is this module's and shares only the queue.
    unsafe { interrupt::TIM5.enable() };
    WheelTimer {
        _timer: timer,
        _hall: hall,
    }
}

#[interrupt]
fn TIM5() {
    let tim = pac::TIM5;
    let sr = tim.sr().read();
    if !sr.ccif(0) {
        return;
    }
    let raw = critical_section::with(|_| RawCapture {
        // Reading CCR1 clears CC1IF.
        capture: tim.ccr(0).read(),
        counter: tim.cnt().read(),
        now_us: Instant::now().as_micros(),
        overcapture: sr.ccof(0),
    });
    if raw.overcapture {
        // rc_w0 flags: write 0 to CC1OF only, 1 (no effect) to the others,
        // so a flag set meanwhile is not cleared by a read-modify-write.
        let mut clear = pac::timer::regs::SrGp16(0);
        clear.set_uif(true);
        clear.set_tif(true);
        for n in 0..4 {
            clear.set_ccif(n, true);
            clear.set_ccof(n, n != 0);
        }
        tim.sr().write_value(clear);
    }
    if EDGES.try_send(raw).is_err() {
        EDGES_LOST.fetch_add(1, Ordering::Relaxed);
    }
}

/// Frames between two reports of lost or refused captures: a failing
/// sensor gets one log line a second, not one a frame.
const REPORT_FRAMES: u32 = 100;

/// The sampler's side of the capture queue.
#[derive(Default)]
pub struct WheelAdapter {
    clock: EdgeClock,
    frames: u32,
    /// Refused captures, overcaptures and queue losses last reported.
    reported: [u32; 3],
}

impl WheelAdapter {
    fn report(&mut self) {
        self.frames = self.frames.wrapping_add(1);
        if !self.frames.is_multiple_of(REPORT_FRAMES) {
            return;
        }
        let CaptureStats {
            refused,
            overcaptures,
            ..
        } = self.clock.stats();
        let now = [refused, overcaptures, EDGES_LOST.load(Ordering::Relaxed)];
        if now != self.reported {
            defmt::warn!(
                "wheel: captures refused {}, overcaptures {}, lost in queue {}",
                now[0],
                now[1],
                now[2]
            );
            self.reported = now;
        }
    }
}

impl WheelPort for WheelAdapter {
    fn drain_edges(&mut self, edge: &mut dyn FnMut(u64)) {
        while let Ok(raw) = EDGES.try_receive() {
            if let Ok(t_us) = self.clock.edge_time_us(raw) {
                edge(t_us);
            }
        }
        self.report();
    }
}
