//! The logger's sensors as the card sees them: each with a bias, white
//! noise, its quantisation and, for the steering potentiometer, rare
//! single-sample spikes (a wiper lifting off its track). The wheel speed is
//! the firmware's own estimator fed with the 50-hole disc's edges.

use wobble_core::wheel::{WheelConfig, WheelSpeed};

use super::super::rng::Rng;
use super::super::signal::{ADC_BITS, ADC_SPAN_DEG};

/// Gyro white noise, deg/s RMS (ICM-42688-P: 2.8 mdps/sqrt(Hz) over the
/// 100 Hz frame rate's band, rounded up for the rack's vibration).
pub const GYRO_NOISE_DPS: f64 = 0.05;
/// Gyro resolution, deg/s (16 bits over +-1000 deg/s).
pub const GYRO_LSB_DPS: f64 = 1.0 / 32.8;
/// Largest gyro bias, deg/s.
pub const GYRO_BIAS_DPS: f64 = 0.5;
/// Accelerometer white noise, g RMS (70 ug/sqrt(Hz), with vibration).
pub const ACCEL_NOISE_G: f64 = 0.002;
/// Accelerometer resolution, g (16 bits over +-16 g).
pub const ACCEL_LSB_G: f64 = 1.0 / 2048.0;
/// Largest accelerometer bias, g.
pub const ACCEL_BIAS_G: f64 = 0.02;
/// Steering potentiometer noise before the ADC, degrees RMS.
pub const STEER_NOISE_DEG: f64 = 0.02;
/// Largest steering calibration offset, degrees.
pub const STEER_BIAS_DEG: f64 = 1.5;
/// Mean time between steering spikes, s.
pub const SPIKE_INTERVAL_S: f64 = 40.0;
/// Size of a steering spike, degrees (either sign).
pub const SPIKE_DEG: (f64, f64) = (2.0, 6.0);

/// One sensor's error model: bias, noise and resolution.
#[derive(Clone, Debug)]
pub struct Channel {
    bias: f64,
    noise: f64,
    lsb: f64,
    rng: Rng,
}

impl Channel {
    /// A channel with a bias drawn within `bias_max`.
    #[must_use]
    pub fn new(mut rng: Rng, bias_max: f64, noise: f64, lsb: f64) -> Self {
        Self {
            bias: rng.range(-bias_max, bias_max),
            noise,
            lsb,
            rng,
        }
    }

    /// What the sensor reads for the true value `x`.
    pub fn read(&mut self, x: f64) -> f64 {
        libm::round((x + self.bias + self.noise * self.rng.normal()) / self.lsb) * self.lsb
    }
}

/// The steering potentiometer and its ADC, with spikes.
#[derive(Clone, Debug)]
pub struct Steering {
    channel: Channel,
    spikes: Rng,
}

impl Steering {
    /// A potentiometer with its own offset, noise and spikes.
    #[must_use]
    pub fn new(rng: &Rng) -> Self {
        let lsb = ADC_SPAN_DEG / f64::from(1u32 << ADC_BITS);
        Self {
            channel: Channel::new(rng.fork(1), STEER_BIAS_DEG, STEER_NOISE_DEG, lsb),
            spikes: rng.fork(2),
        }
    }

    /// The reading for the true angle, and the spike added to it (0 for
    /// none), degrees; `fs_hz` is the sample rate.
    pub fn read(&mut self, steer_deg: f64, fs_hz: f64) -> (f64, f64) {
        let spike = if self.spikes.uniform() < 1.0 / (SPIKE_INTERVAL_S * fs_hz) {
            self.spikes.sign() * self.spikes.range(SPIKE_DEG.0, SPIKE_DEG.1)
        } else {
            0.0
        };
        let half = ADC_SPAN_DEG / 2.0;
        let v = self.channel.read(steer_deg + spike);
        (v.clamp(-half, half - self.channel.lsb), spike)
    }
}

/// The wheel-speed sensor: edges of the disc's holes into the firmware's
/// estimator.
#[derive(Clone, Debug)]
pub struct Wheel {
    est: WheelSpeed,
    pitch_m: f64,
    distance_m: f64,
    next_edge_m: f64,
}

impl Wheel {
    /// The firmware's default wheel.
    #[must_use]
    pub fn new() -> Self {
        let config = WheelConfig::default();
        let est = WheelSpeed::try_new(config).unwrap_or_else(|_| unreachable!("default wheel"));
        Self {
            pitch_m: f64::from(config.pitch_m()),
            est,
            distance_m: 0.0,
            next_edge_m: 0.0,
        }
    }

    /// Rolls on for `dt_s` from `t_s` at `speed_mps`, feeding every edge,
    /// and returns the estimate at the end.
    pub fn roll(&mut self, t_s: f64, dt_s: f64, speed_mps: f64) -> f64 {
        let end_m = self.distance_m + speed_mps * dt_s;
        while self.next_edge_m <= end_m && speed_mps > 0.0 {
            let t = t_s + (self.next_edge_m - self.distance_m) / speed_mps;
            let _ = self.est.on_edge((t * 1e6) as u64);
            self.next_edge_m += self.pitch_m;
        }
        self.distance_m = end_m;
        f64::from(self.est.speed_mps(((t_s + dt_s) * 1e6) as u64))
    }
}

impl Default for Wheel {
    fn default() -> Self {
        Self::new()
    }
}
