//! Rider I/O: buzzer and alert LED (driven by the core's alert pattern),
//! the marker button and the status LED.

use embassy_stm32::gpio::{Input, Output};
use wobble_core::app::ports::{AlertOutput, LoggerHealth, MarkerInput, StatusLed};

/// Buzzer and alert LED; silent when `CONFIG.TXT` says `alert.enabled=false`
/// (the alerts are still detected and logged).
pub struct AlertPins {
    /// Active buzzer.
    pub buzzer: Output<'static>,
    /// Alert LED.
    pub led: Output<'static>,
    /// Whether to tell the rider.
    pub enabled: bool,
}

impl AlertOutput for AlertPins {
    fn set_buzzer(&mut self, on: bool) {
        self.buzzer.set_level((on && self.enabled).into());
    }

    fn set_led(&mut self, on: bool) {
        self.led.set_level((on && self.enabled).into());
    }
}

/// The marker button, active low.
pub struct MarkerButton(pub Input<'static>);

impl MarkerInput for MarkerButton {
    fn is_pressed(&mut self) -> bool {
        self.0.is_low()
    }
}

/// Frames per blink half-period: degraded blinks at 1 Hz, no card at 5 Hz.
const DEGRADED_HALF_FRAMES: u32 = 50;
const NO_CARD_HALF_FRAMES: u32 = 10;

/// Status LED: steady on while logging with every sensor fine, slow blink
/// when a sensor fails or the GPS has no fix, fast blink without a card.
/// Called once per frame, it is also the sampler's watchdog heartbeat.
pub struct StatusLight {
    /// The LED.
    pub led: Output<'static>,
    /// Frames shown so far (the blink clock: `show` runs once per frame).
    pub frames: u32,
}

impl StatusLed for StatusLight {
    fn show(&mut self, health: LoggerHealth) {
        crate::watchdog::SAMPLER.beat();
        self.frames = self.frames.wrapping_add(1);
        let on = match health {
            LoggerHealth::Ok => true,
            LoggerHealth::Degraded => (self.frames / DEGRADED_HALF_FRAMES) & 1 == 0,
            LoggerHealth::NoCard => (self.frames / NO_CARD_HALF_FRAMES) & 1 == 0,
        };
        self.led.set_level(on.into());
    }
}
