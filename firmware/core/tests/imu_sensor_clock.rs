//! The IMU on its own clock: a simulated ICM-42688-P whose output data rate
//! drifts ±2 % against the MCU's 10 ms tick, behind the real driver and
//! port (`Icm42688Port` with a data-ready line), in virtual time.
//!
//! Each simulated sample carries its own index in accel x (and its negative
//! in gyro x), and the signal is linear in time, so a frame's value tells
//! exactly which instant of the sensor's output it holds. With the
//! data-ready times every frame must hold the output of exactly
//! `AGE_US` before its tick, every sample must be used, none counted lost,
//! also through a 66 ms stall and through one of 1.23 s, as long as the
//! FIFO holds. The once-per-tick read of the data registers (the port
//! without a data-ready line, as the board read before) gets the 0-10 ms
//! sawtooth, repeated and missed samples: the last test
//! shows it.

mod icm42688_support;

use std::cell::RefCell;
use std::collections::VecDeque;
use std::convert::Infallible;
use std::rc::Rc;

use embassy_futures::block_on;
use embassy_time::{Duration, Instant, MockDriver};
use embedded_hal_async::spi::{ErrorType, Operation, SpiDevice};
use embedded_hal_mock::eh1::delay::NoopDelay;
use wobble_core::app::imu_port::Icm42688Port;
use wobble_core::app::ports::{DataReadyPort, ImuPort, ImuSample, SensorError};
use wobble_core::drivers::icm42688::{reg, Config, Icm42688};
use wobble_core::imu::{Imu, ImuConfig};
use wobble_core::imu_clock::{AGE_US, FIFO_CAPACITY};
use wobble_core::stall::LONGEST_STALL_US;

const TICK_US: u64 = 10_000;
/// Bus time of one SPI transaction in the simulation, µs: long enough for
/// samples to land between the port's steps.
const TRANSACTION_US: u64 = 7;

/// The sensor: samples at `t0 + k × period` (MCU µs), into its FIFO and
/// data registers, a data-ready pulse each.
struct Sensor {
    t0_us: f64,
    period_us: f64,
    produced: u64,
    on: bool,
    fifo: VecDeque<u64>,
    newest: Option<u64>,
    pulses: VecDeque<u64>,
}

impl Sensor {
    fn time_of(&self, k: f64) -> f64 {
        self.t0_us + k * self.period_us
    }

    /// Makes every sample due by now.
    fn catch_up(&mut self) {
        let now = Instant::now().as_micros() as f64;
        while self.time_of(self.produced as f64) <= now {
            let k = self.produced;
            self.produced += 1;
            if !self.on {
                continue;
            }
            // Stream mode: a full FIFO drops its oldest sample.
            if self.fifo.len() == FIFO_CAPACITY {
                self.fifo.pop_front();
            }
            self.fifo.push_back(k);
            self.newest = Some(k);
            self.pulses.push_back(self.time_of(k as f64) as u64);
        }
    }
}

/// Accel x = k, y = 1 g, z = 0; gyro x = −k.
fn words(k: u64) -> [i16; 6] {
    let k = i16::try_from(k).expect("runs shorter than 32 767 samples");
    [k, 2048, 0, -k, 5, 9]
}

fn bytes(words: [i16; 6]) -> Vec<u8> {
    words.iter().flat_map(|w| w.to_be_bytes()).collect()
}

#[derive(Clone)]
struct Bus(Rc<RefCell<Sensor>>);

impl ErrorType for Bus {
    type Error = Infallible;
}

impl SpiDevice for Bus {
    async fn transaction(&mut self, ops: &mut [Operation<'_, u8>]) -> Result<(), Infallible> {
        MockDriver::get().advance(Duration::from_micros(TRANSACTION_US));
        let mut s = self.0.borrow_mut();
        s.catch_up();
        let mut address = None;
        for op in ops {
            match op {
                // The first byte is the address; a write's value follows.
                Operation::Write(w) if address.is_none() => {
                    address = Some(w[0]);
                    if let (false, [value, ..]) = (w[0] & reg::READ != 0, &w[1..]) {
                        match w[0] {
                            reg::PWR_MGMT0 => s.on = true,
                            reg::DEVICE_CONFIG => s.on = false,
                            reg::SIGNAL_PATH_RESET if value & reg::FIFO_FLUSH != 0 => {
                                s.fifo.clear();
                            }
                            _ => {}
                        }
                    }
                }
                Operation::Read(out) => {
                    let answer = match address.map(|a| a & !reg::READ) {
                        Some(reg::WHO_AM_I) => vec![reg::WHO_AM_I_VALUE],
                        Some(reg::FIFO_COUNTH) => {
                            let n = (s.fifo.len() * reg::PACKET3_LEN) as u16;
                            n.to_be_bytes().to_vec()
                        }
                        Some(reg::FIFO_DATA) => match s.fifo.pop_front() {
                            Some(k) => {
                                let mut p = vec![0x68];
                                p.extend(bytes(words(k)));
                                p.extend([25, 0, 0]);
                                p
                            }
                            None => vec![0x80; reg::PACKET3_LEN],
                        },
                        Some(reg::ACCEL_DATA_X1) => match s.newest {
                            Some(k) => bytes(words(k)),
                            None => bytes([reg::NO_DATA; 6]),
                        },
                        _ => vec![0; out.len()],
                    };
                    out.copy_from_slice(&answer[..out.len()]);
                }
                _ => {}
            }
        }
        Ok(())
    }
}

/// The data-ready line, its pulses latched by a timer.
struct Pulses(Rc<RefCell<Sensor>>);

impl DataReadyPort for Pulses {
    const WIRED: bool = true;

    fn drain_pulses(&mut self, pulse: &mut dyn FnMut(u64) -> bool) {
        let mut s = self.0.borrow_mut();
        s.catch_up();
        while let Some(t) = s.pulses.pop_front() {
            if !pulse(t) {
                break;
            }
        }
    }
}

fn sensor(drift: f64, phase: f64) -> Rc<RefCell<Sensor>> {
    let period_us = TICK_US as f64 * (1.0 + drift);
    Rc::new(RefCell::new(Sensor {
        t0_us: Instant::now().as_micros() as f64 + phase * period_us,
        period_us,
        produced: 0,
        on: false,
        fifo: VecDeque::new(),
        newest: None,
        pulses: VecDeque::new(),
    }))
}

fn channel() -> Imu {
    Imu::try_new(Config::default().imu_config(ImuConfig::DEFAULT)).expect("ranges")
}

/// The sample index a frame's value holds (accel x in counts).
fn index_of(s: &ImuSample) -> f64 {
    f64::from(s.accel_g[0]) * 2048.0
}

/// Reads `frames` frames at 100 Hz, each late by a pseudo-random 0-0.8 ms
/// and, with `stall` = (frame, µs), a stall at that frame whose missed
/// ticks are read back to back; returns (tick, answer) per frame.
fn ride(
    port: &mut impl ImuPort,
    frames: u64,
    stall: Option<(u64, u64)>,
) -> Vec<(u64, Result<ImuSample, SensorError>)> {
    let start = Instant::now().as_micros();
    let mut seed = 0x2545_f491_u64;
    let mut out = Vec::new();
    for k in 1..=frames {
        let tick = start + k * TICK_US;
        seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        let mut read_at = tick + (seed >> 33) % 800;
        if let Some((_, us)) = stall.filter(|&(at, _)| at == k) {
            read_at = tick + us;
        }
        let now = Instant::now().as_micros();
        if read_at > now {
            MockDriver::get().advance(Duration::from_micros(read_at - now));
        }
        out.push((tick, block_on(port.read(tick))));
    }
    out
}

// One test: the mock clock is shared by every test of this binary.
#[test]
fn frames_hold_the_sensor_output_at_a_fixed_age_whatever_the_drift() {
    let drifts = [-0.02, -0.015, -0.01, -0.003, 0.0, 0.003, 0.01, 0.015, 0.02];
    let longest = u64::from(LONGEST_STALL_US);
    fixed_age_through_a_stall(&drifts, &[0.0, 0.31, 0.77, 0.99], longest);
    // A stall as long as the FIFO holds, the sensor 2 % fast at most: the
    // FIFO keeps every sample, and each catch-up frame gets its own.
    let fifo_full = FIFO_CAPACITY as u64 * TICK_US * 96 / 100;
    fixed_age_through_a_stall(&[-0.02, 0.0, 0.02], &[0.0, 0.77], fifo_full);
    the_read_once_per_tick_has_a_sawtooth_age_and_repeats_and_misses_samples();
}

/// Every frame after the first two holds the sensor's output `AGE_US`
/// before its tick, none skipped, through a stall of `stall_us` at frame
/// 300, for each drift and phase.
fn fixed_age_through_a_stall(drifts: &[f64], phases: &[f64], stall_us: u64) {
    for &drift in drifts {
        for &phase in phases {
            let s = sensor(drift, phase);
            let driver = Icm42688::new(Bus(s.clone()), Config::default());
            let mut port = Icm42688Port::with_data_ready(
                driver,
                channel(),
                NoopDelay::new(),
                Pulses(s.clone()),
            );
            block_on(port.start());
            let frames = ride(&mut port, 600, Some((300, stall_us)));
            let sensor = s.borrow();
            for (n, (tick, answer)) in frames.iter().enumerate().skip(2) {
                let sample = answer.unwrap_or_else(|e| {
                    panic!("stall {stall_us} µs, drift {drift} frame {n}: {e:?}")
                });
                let t = sensor.time_of(index_of(&sample));
                let age = *tick as f64 - t;
                assert!(
                    (age - AGE_US as f64).abs() < 3.0,
                    "stall {stall_us} µs, drift {drift} phase {phase} frame {n}: age {age} µs"
                );
                assert_eq!(
                    sample.skipped, 0,
                    "stall {stall_us} µs, drift {drift} frame {n}"
                );
                assert!((sample.gyro_dps[0] * 65.5 + sample.accel_g[0] * 2048.0).abs() < 0.05);
            }
            let (stats, period) = port.clock();
            assert_eq!(stats.skipped, 0, "{stats:?}");
            assert_eq!(stats.untimed, 0, "{stats:?}");
            // The first frames come before the sensor's first samples.
            assert!(stats.late <= 2, "{stats:?}");
            // Every sample made since the start, but those still in the
            // FIFO's last moments, was used.
            assert!(
                sensor.produced - u64::from(stats.samples) <= 8,
                "{} made, {stats:?}",
                sensor.produced
            );
            assert!(
                (f64::from(period) / sensor.period_us - 1.0).abs() < 1e-3,
                "period {period} for {}",
                sensor.period_us
            );
        }
    }
}

/// What the board did before, for the record: the newest register sample,
/// once per tick, against a sensor 1 % fast.
fn the_read_once_per_tick_has_a_sawtooth_age_and_repeats_and_misses_samples() {
    let s = sensor(-0.01, 0.5);
    let mut port = Icm42688Port::new(
        Icm42688::new(Bus(s.clone()), Config::default()),
        channel(),
        NoopDelay::new(),
    );
    block_on(port.start());
    let frames = ride(&mut port, 600, None);
    let sensor = s.borrow();
    let mut ages = Vec::new();
    let mut indices = Vec::new();
    for (tick, answer) in frames.iter().skip(2) {
        let sample = answer.expect("a sample");
        let k = index_of(&sample);
        ages.push(*tick as f64 - sensor.time_of(k));
        indices.push(k.round() as i64);
    }
    let spread = ages.iter().cloned().fold(f64::MIN, f64::max)
        - ages.iter().cloned().fold(f64::MAX, f64::min);
    assert!(spread > 9_000.0, "age spread {spread} µs");
    let missed = indices.windows(2).filter(|w| w[1] - w[0] > 1).count();
    assert!(missed >= 5, "{missed} samples never reached a frame");
}
