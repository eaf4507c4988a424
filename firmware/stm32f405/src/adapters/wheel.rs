//! TIM5's input captures: the wheel's hall sensor on channel 1 and the
//! IMU's data-ready line (INT1) on channel 2. The timer latches its 32-bit
//! count (1 µs per count) at each edge in hardware; the capture interrupt
//! reads the latched count, the running count and the clock, and queues
//! the three for the sampler, which turns them into edge times with the
//! core's [`EdgeClock`] (one per channel).
//!
//! Own interrupt handler, not embassy-stm32's input capture: its 0.6.0
//! future returns the capture through the 16-bit timer view (a 32-bit count
//! masked to 16 bits), and it rewrites the input filter to "none" on every
//! wait. Here the 32-bit CCRx are read through the PAC and the filter stays.

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
use embassy_stm32::timer::{Ch1, Ch2, Channel as TimerChannel};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_time::Instant;
use wobble_core::app::ports::{DataReadyPort, WheelPort};
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

/// IMU data-ready pulses waiting: one per 10 ms frame, and one per sample
/// the sensor's FIFO holds after a stall (1.28 s), so that every sample of
/// such a stall keeps its own time.
const PULSE_QUEUE_LEN: usize = wobble_core::imu_clock::FIFO_CAPACITY + 8;

/// Capture interrupt -> sampler: wheel edges (channel 1).
static EDGES: Channel<CriticalSectionRawMutex, RawCapture, EDGE_QUEUE_LEN> = Channel::new();
/// Capture interrupt -> sampler: IMU data-ready pulses (channel 2).
static PULSES: Channel<CriticalSectionRawMutex, RawCapture, PULSE_QUEUE_LEN> = Channel::new();
/// Captures lost because the sampler did not drain a queue: wheel, IMU.
static LOST: [AtomicU32; 2] = [AtomicU32::new(0), AtomicU32::new(0)];

/// The timer and its pins, kept configured for as long as this lives
/// (dropping the timer would stop its clock).
pub struct WheelTimer {
    _timer: Timer<'static, TIM5>,
    _hall: CapturePin<'static, TIM5, Ch1>,
    _imu_int1: CapturePin<'static, TIM5, Ch2>,
}

/// Configures TIM5 as a free-running 32-bit 1 MHz counter capturing
/// falling edges on PA0 (the wheel) and rising edges on PA1 (the IMU's
/// data-ready pulses), and enables its interrupt.
pub fn start(pins: WheelPins) -> WheelTimer {
    // The sensor is open collector: the internal pull-up (about 40 kΩ)
    // holds the line high; see the pin table for the external one.
    let hall = CapturePin::new(pins.hall, embassy_stm32::gpio::Pull::Up);
    // INT1 is push-pull, active high: the pull-down only keeps an unwired
    // or unpowered sensor's line from floating.
    let imu_int1 = CapturePin::new(pins.imu_int1, embassy_stm32::gpio::Pull::Down);
    let mut timer = Timer::new(pins.timer);
    timer.set_counting_mode(CountingMode::EdgeAlignedUp);
    timer.set_tick_freq(Hertz(TICK_HZ));
    // The whole 32-bit range, explicitly: the age arithmetic wraps at 2^32.
    timer.set_max_compare_value(u32::MAX);
    for (ch, mode) in [
        (TimerChannel::Ch1, InputCaptureMode::Falling),
        (TimerChannel::Ch2, InputCaptureMode::Rising),
    ] {
        // TI2 into IC2 ("Normal"), CC2S = 01: channel 2 captures its own pin.
        timer.set_input_ti_selection(ch, InputTISelection::Normal);
        // The 3 µs filter delays every pulse by the same 3 µs: the age
        // of an IMU value is AGE_US plus that, for all frames alike.
        timer.set_input_capture_filter(ch, FILTER);
        timer.set_input_capture_mode(ch, mode);
        timer.set_input_capture_prescaler(ch, 0);
        timer.enable_channel(ch, true);
        timer.clear_input_interrupt(ch);
        timer.enable_input_interrupt(ch, true);
    }
    timer.start();
    interrupt::TIM5.set_priority(IRQ_PRIORITY);
    interrupt::TIM5.unpend();
    // SAFETY: the handler below is this module's and shares only the queue.
    unsafe { interrupt::TIM5.enable() };
    WheelTimer {
        _timer: timer,
        _hall: hall,
        _imu_int1: imu_int1,
    }
}

#[interrupt]
fn TIM5() {
    let tim = pac::TIM5;
    let sr = tim.sr().read();
    for n in [0, 1] {
        if !sr.ccif(n) {
            continue;
        }
        let raw = critical_section::with(|_| RawCapture {
            // Reading CCRx clears CCxIF.
            capture: tim.ccr(n).read(),
            counter: tim.cnt().read(),
            now_us: Instant::now().as_micros(),
            overcapture: sr.ccof(n),
        });
        if raw.overcapture {
            // rc_w0 flags: write 0 to this CCxOF only, 1 (no effect) to
            // the others, so a flag set meanwhile is not cleared by a
            // read-modify-write.
            let mut clear = pac::timer::regs::SrGp16(0);
            clear.set_uif(true);
            clear.set_tif(true);
            for m in 0..4 {
                clear.set_ccif(m, true);
                clear.set_ccof(m, m != n);
            }
            tim.sr().write_value(clear);
        }
        // The two queues differ in length, hence in type.
        let sent = if n == 0 {
            EDGES.try_send(raw)
        } else {
            PULSES.try_send(raw)
        };
        if sent.is_err() {
            LOST[n].fetch_add(1, Ordering::Relaxed);
        }
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
        let now = [refused, overcaptures, LOST[0].load(Ordering::Relaxed)];
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

/// The IMU's data-ready pulses for the core's IMU port: the second
/// capture channel's queue through its own [`EdgeClock`]. A pulse lost in
/// the queue or in hardware (an overcapture) is found by the core's
/// `imu_clock` as a sample without its pulse, and counted there.
#[derive(Default)]
pub struct DataReadyAdapter {
    clock: EdgeClock,
}

impl DataReadyAdapter {
    /// Pulses refused by the edge clock, and lost in the queue.
    pub fn losses(&self) -> (u32, u32) {
        (self.clock.stats().refused, LOST[1].load(Ordering::Relaxed))
    }
}

impl DataReadyPort for DataReadyAdapter {
    const WIRED: bool = true;

    fn drain_pulses(&mut self, pulse: &mut dyn FnMut(u64) -> bool) {
        while let Ok(raw) = PULSES.try_receive() {
            if let Ok(t_us) = self.clock.edge_time_us(raw) {
                if !pulse(t_us) {
                    break;
                }
            }
        }
    }
}
