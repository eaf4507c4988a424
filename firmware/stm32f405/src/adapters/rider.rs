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

/// Status LED, as [`LoggerHealth::led_on`] says.
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
        self.led.set_level(health.led_on(self.frames).into());
    }
}
