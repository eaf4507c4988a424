//! Sensors replayed from the harness's fixture files in QEMU's working
//! directory, through semihosting:
//!
//! - `ride.bin`, one row per 10 ms frame, as the sensors produce it: the
//!   IMU's 12 data registers (accel x/y/z then gyro x/y/z in the sensor's
//!   axes, big-endian words, as `ACCEL_DATA_X1` onwards reads), `adc` u8,
//!   then `adc` × u16: the steering ADC's conversions in the frame (counts),
//!   `edges` u8, then `edges` × u16: each wheel edge's age in µs before the
//!   frame's time; little-endian unless said;
//! - `gps.bin`, the NMEA capture's bytes as they arrived: records of
//!   `t_ms` u32 (since boot), `len` u16, `len` bytes.
//!
//! The wheel port is drained first in every tick, so it advances the row
//! the IMU (`imu_bus.rs`) and steering ports then read.

use core::cell::RefCell;

use embassy_time::{Instant, Timer};
use semihosting::fs::File;
use semihosting::io::Read;
use wobble_core::app::ports::{
    GpsPort, MarkerInput, SensorError, SteeringPort, SteeringSample, WheelPort,
};
use wobble_core::steering::Steering;

use crate::scenario::{within, Scenario};

/// A semihosting file read through a small buffer (each semihosting call
/// traps to the host, so rows are not read one by one).
struct Buffered {
    file: Option<File>,
    buf: [u8; 512],
    pos: usize,
    len: usize,
}

impl Buffered {
    fn open(path: &core::ffi::CStr) -> Self {
        Self {
            file: File::open(path).ok(),
            buf: [0; 512],
            pos: 0,
            len: 0,
        }
    }

    fn byte(&mut self) -> Option<u8> {
        if self.pos == self.len {
            self.len = self.file.as_mut()?.read(&mut self.buf).ok()?;
            self.pos = 0;
            if self.len == 0 {
                return None;
            }
        }
        self.pos += 1;
        Some(self.buf[self.pos - 1])
    }

    fn u16(&mut self) -> Option<u16> {
        Some(u16::from_le_bytes([self.byte()?, self.byte()?]))
    }

    fn u32(&mut self) -> Option<u32> {
        Some(u32::from(self.u16()?) | u32::from(self.u16()?) << 16)
    }
}

/// Most wheel edges in one 10 ms row (240 pulses/s at 10 m/s is 2.4).
const MAX_EDGES: usize = 16;
/// Most ADC conversions in one row.
pub const MAX_ADC: usize = 32;
/// Bytes of the IMU's data registers (ACCEL_DATA_X1 .. GYRO_DATA_Z0).
pub const IMU_DATA_LEN: usize = 12;

/// One row as the sensors produce it.
struct Row {
    imu_regs: [u8; IMU_DATA_LEN],
    adc: heapless::Vec<u16, MAX_ADC>,
    edges_age_us: heapless::Vec<u16, MAX_EDGES>,
}

fn read_row(f: &mut Buffered) -> Option<Row> {
    let mut imu_regs = [0; IMU_DATA_LEN];
    for b in &mut imu_regs {
        *b = f.byte()?;
    }
    let mut adc = heapless::Vec::new();
    for _ in 0..f.byte()? {
        // More conversions than the buffer holds: keep the first ones.
        let _ = adc.push(f.u16()?);
    }
    let mut edges_age_us = heapless::Vec::new();
    for _ in 0..f.byte()? {
        // More edges than a wheel can make in 10 ms: keep the first ones.
        let _ = edges_age_us.push(f.u16()?);
    }
    Some(Row {
        imu_regs,
        adc,
        edges_age_us,
    })
}

/// The ride being replayed.
pub struct Ride {
    file: Buffered,
    row: Option<Row>,
}

impl Ride {
    pub fn open() -> Self {
        Self {
            file: Buffered::open(c"ride.bin"),
            row: None,
        }
    }

    /// The next row for the detector benchmark: its steering sample
    /// through `channel` (`Stale` without a conversion), after handing each
    /// of its wheel edges' ages (µs, oldest first) to `edge_age_us`; `None`
    /// at the end.
    pub fn next_bench_row(
        &mut self,
        channel: &mut Steering,
        edge_age_us: &mut impl FnMut(u16),
    ) -> Option<Result<SteeringSample, SensorError>> {
        let row = read_row(&mut self.file)?;
        row.edges_age_us.iter().rev().for_each(|&a| edge_age_us(a));
        channel.push_all(&row.adc);
        Some(channel.take().ok_or(SensorError::Stale))
    }

    /// The current row's IMU data registers.
    pub fn imu_regs(&self) -> Option<[u8; IMU_DATA_LEN]> {
        self.row.as_ref().map(|r| r.imu_regs)
    }
}

/// The wheel sensor and the marker button over the shared ride.
#[derive(Clone, Copy)]
pub struct Port(pub &'static RefCell<Ride>);

impl WheelPort for Port {
    fn drain_edges(&mut self, edge: &mut dyn FnMut(u64)) {
        let mut ride = self.0.borrow_mut();
        let row = read_row(&mut ride.file);
        let now_us = Instant::now().as_micros();
        if let Some(row) = &row {
            // Oldest first: the largest age first.
            for &age in row.edges_age_us.iter().rev() {
                edge(now_us.saturating_sub(u64::from(age)));
            }
        }
        ride.row = row;
        crate::FRAMES_SAMPLED.fetch_add(1, core::sync::atomic::Ordering::Relaxed);
    }
}

impl MarkerInput for Port {
    fn is_pressed(&mut self) -> bool {
        false
    }
}

/// The steering potentiometer's ADC: the row's conversions into the core's
/// steering channel (averaging, calibration, saturation), as the board's
/// DMA ring hands them over. An open wiper (the scenario's window) reads
/// full scale, as the board's pull-up makes it.
pub struct ReplayedAdc {
    ride: &'static RefCell<Ride>,
    channel: Steering,
    scenario: &'static Scenario,
}

impl ReplayedAdc {
    pub fn new(
        ride: &'static RefCell<Ride>,
        channel: Steering,
        scenario: &'static Scenario,
    ) -> Self {
        Self {
            ride,
            channel,
            scenario,
        }
    }
}

impl SteeringPort for ReplayedAdc {
    // Each frame replays its own fixture row, however late it is read.
    async fn read(&mut self, _late_us: u64) -> Result<SteeringSample, SensorError> {
        let ride = self.ride.borrow();
        let row = ride.row.as_ref().ok_or(SensorError::Stale)?;
        if within(self.scenario.steer_open_ms, Instant::now().as_millis()) {
            let full = self.channel.calibration().adc_max;
            for _ in &row.adc {
                self.channel.push(full);
            }
        } else {
            self.channel.push_all(&row.adc);
        }
        self.channel.take().ok_or(SensorError::Stale)
    }
}

/// The GPS UART, replaying `gps.bin` on time.
pub struct Gps {
    file: Buffered,
    /// The chunk due next: arrival time and bytes not yet handed out.
    pending: Option<(u64, heapless::Vec<u8, 256>)>,
    scenario: &'static Scenario,
    noise: u32,
}

impl Gps {
    pub fn open(scenario: &'static Scenario) -> Self {
        Self {
            file: Buffered::open(c"gps.bin"),
            pending: None,
            scenario,
            noise: 0x1234_5678,
        }
    }

    fn next_chunk(&mut self) -> Option<(u64, heapless::Vec<u8, 256>)> {
        let t_ms = self.file.u32()?;
        let len = self.file.u16()?;
        let mut bytes = heapless::Vec::new();
        for _ in 0..len {
            let b = self.file.byte()?;
            // Longer records are cut: the harness writes short ones.
            let _ = bytes.push(b);
        }
        Some((u64::from(t_ms), bytes))
    }

    /// xorshift32: noise that is not NMEA but has its '$' and line ends.
    fn garble(&mut self, bytes: &mut [u8]) {
        for b in bytes {
            self.noise ^= self.noise << 13;
            self.noise ^= self.noise >> 17;
            self.noise ^= self.noise << 5;
            *b = self.noise as u8;
        }
    }
}

impl GpsPort for Gps {
    async fn read(&mut self, buf: &mut [u8]) -> usize {
        if self.pending.is_none() {
            self.pending = self.next_chunk();
        }
        let Some((t_ms, _)) = &self.pending else {
            return 0;
        };
        Timer::at(embassy_time::Instant::from_millis(*t_ms)).await;
        let Some((t_ms, mut bytes)) = self.pending.take() else {
            return 0;
        };
        let n = bytes.len().min(buf.len());
        if within(self.scenario.gps_garbage_ms, t_ms) {
            self.garble(&mut bytes[..n]);
        }
        buf[..n].copy_from_slice(&bytes[..n]);
        if n < bytes.len() {
            let rest = heapless::Vec::from_slice(&bytes[n..]).unwrap_or_default();
            self.pending = Some((t_ms, rest));
        }
        n
    }
}
