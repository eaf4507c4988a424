//! Sensors replayed from the harness's fixture files in QEMU's working
//! directory, through semihosting:
//!
//! - `ride.bin`, one row per 10 ms frame: `steer_cdeg` i16, `accel` i16 ×3
//!   (1/2048 g), `gyro` i16 ×3 (1/32 deg/s), `edges` u8, then `edges` × u16:
//!   each wheel edge's age in µs before the frame's time; little-endian;
//! - `gps.bin`, the NMEA capture's bytes as they arrived: records of
//!   `t_ms` u32 (since boot), `len` u16, `len` bytes.
//!
//! The wheel port is drained first in every tick, so it advances the row
//! the IMU and steering ports then read.

use core::cell::RefCell;

use embassy_time::{Instant, Timer};
use semihosting::fs::File;
use semihosting::io::Read;
use wobble_core::app::ports::{
    GpsPort, ImuPort, ImuSample, MarkerInput, SensorError, SteeringPort, SteeringSample, WheelPort,
};
use wobble_core::format::{ACCEL_COUNTS_PER_G, GYRO_COUNTS_PER_DPS, STEER_COUNTS_PER_DEG};

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

    fn i16(&mut self) -> Option<i16> {
        self.u16().map(|v| v as i16)
    }

    fn u32(&mut self) -> Option<u32> {
        Some(u32::from(self.u16()?) | u32::from(self.u16()?) << 16)
    }
}

/// Most wheel edges in one 10 ms row (240 pulses/s at 10 m/s is 2.4).
const MAX_EDGES: usize = 16;

/// One row as the sensor channels would deliver it. The fixture's counts
/// are the card's units, which are powers of two (IMU) or 100 (steering):
/// frame assembly quantises these values back to exactly the same counts.
struct Row {
    steering: SteeringSample,
    imu: ImuSample,
    edges_age_us: heapless::Vec<u16, MAX_EDGES>,
}

fn read_row(f: &mut Buffered) -> Option<Row> {
    let steering = SteeringSample {
        deg: f32::from(f.i16()?) / STEER_COUNTS_PER_DEG,
        saturated: false,
    };
    let mut imu = ImuSample::default();
    for g in &mut imu.accel_g {
        *g = f32::from(f.i16()?) / ACCEL_COUNTS_PER_G;
    }
    for dps in &mut imu.gyro_dps {
        *dps = f32::from(f.i16()?) / GYRO_COUNTS_PER_DPS;
    }
    let n = f.byte()?;
    let mut edges_age_us = heapless::Vec::new();
    for _ in 0..n {
        let age = f.u16()?;
        // More edges than a wheel can make in 10 ms: keep the first ones.
        let _ = edges_age_us.push(age);
    }
    Some(Row {
        steering,
        imu,
        edges_age_us,
    })
}

/// The ride being replayed.
pub struct Ride {
    file: Buffered,
    row: Option<Row>,
    scenario: &'static Scenario,
}

impl Ride {
    pub fn open(scenario: &'static Scenario) -> Self {
        Self {
            file: Buffered::open(c"ride.bin"),
            row: None,
            scenario,
        }
    }
}

impl Ride {
    /// The next frame's steering angle, degrees; `None` at the end.
    pub fn next_steer_deg(&mut self) -> Option<f32> {
        read_row(&mut self.file).map(|row| row.steering.deg)
    }
}

/// One sensor's view of the shared ride.
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

impl ImuPort for Port {
    async fn read(&mut self) -> Result<ImuSample, SensorError> {
        let ride = self.0.borrow();
        if ride
            .scenario
            .imu_dead_from_ms
            .is_some_and(|t| Instant::now().as_millis() >= u64::from(t))
        {
            return Err(SensorError::NoResponse);
        }
        ride.row.as_ref().map(|r| r.imu).ok_or(SensorError::Stale)
    }
}

impl SteeringPort for Port {
    async fn read(&mut self) -> Result<SteeringSample, SensorError> {
        let ride = self.0.borrow();
        ride.row
            .as_ref()
            .map(|r| r.steering)
            .ok_or(SensorError::Stale)
    }
}

impl MarkerInput for Port {
    fn is_pressed(&mut self) -> bool {
        false
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
