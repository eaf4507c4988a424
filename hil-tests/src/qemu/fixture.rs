//! The files a QEMU run replays: `ride.bin` (per 10 ms frame the IMU's
//! data registers, the steering ADC's conversions and the wheel edges, as
//! the sensors produce them) from a corpus ride, and `gps.bin` (NMEA bytes
//! with their arrival times) from a real receiver capture. Layouts are
//! documented in `qemu-image/src/replay.rs`.

use std::path::{Path, PathBuf};

use wobble_core::config::Config;
use wobble_core::drivers::icm42688;
use wobble_core::imu::AxisMap;
use wobble_core::steering::SteeringCalibration;
use wobble_core::wheel::WheelConfig;

use crate::corpus::rng::Rng;
use crate::corpus::{self, FixtureTruth, Row};

/// Frame period, µs.
pub const FRAME_US: u64 = 10_000;
/// UART character time at the receiver's 115 200 baud (8N1), µs.
const CHAR_US: f64 = 10.0 * 1e6 / 115_200.0;
/// Longest `gps.bin` record the image takes (its buffer), bytes.
const MAX_GPS_RECORD: usize = 200;

/// A corpus ride and its ground truth.
#[derive(Clone, Debug)]
pub struct CorpusRide {
    /// 100 Hz rows.
    pub rows: Vec<Row>,
    /// Ground truth from the manifest.
    pub truth: FixtureTruth,
}

/// Loads corpus fixture `name`: the committed CSV if present, else the
/// generator's output (the same bytes: a corpus test checks that).
///
/// # Errors
/// No fixture of that name, or an unreadable CSV.
pub fn corpus_ride(name: &str) -> Result<CorpusRide, String> {
    let dir = corpus::corpus_dir();
    let manifest = std::fs::read_to_string(dir.join("manifest.json"))
        .ok()
        .and_then(|text| serde_json::from_str::<corpus::Manifest>(&text).ok());
    let committed = manifest.and_then(|m| m.fixtures.into_iter().find(|f| f.name == name));
    if let Some(truth) = committed {
        if let Ok(csv) = std::fs::read_to_string(corpus::fixture_path(&dir, &truth)) {
            return Ok(CorpusRide {
                rows: corpus::parse_rows(&csv)?,
                truth,
            });
        }
    }
    let fixture = corpus::generate()
        .into_iter()
        .find(|f| f.truth.name == name)
        .ok_or_else(|| format!("no corpus fixture named {name}"))?;
    Ok(CorpusRide {
        rows: fixture.rows()?,
        truth: fixture.truth,
    })
}

/// Steering ADC conversions per frame in `ride.bin` (the board makes about
/// 427; eight already show the averaging resolving a fraction of a count).
pub const ADC_PER_FRAME: usize = 8;
/// The IMU's offsets in the bicycle frame (zero-g and zero-rate errors),
/// different on every axis so that a wrong axis map shows.
pub const ACCEL_BIAS_G: [f64; 3] = [0.02, -0.015, 0.01];
/// See [`ACCEL_BIAS_G`].
pub const GYRO_BIAS_DPS: [f64; 3] = [0.4, -0.25, 0.15];
/// The IMU's noise, peak, LSB (uniform): real MEMS output changes on
/// every sample, which the stuck check relies on.
pub const IMU_NOISE_LSB: f64 = 2.0;
const WHEELBASE_M: f64 = 1.1;

/// What the IMU measures in the bicycle frame for `row` (g, deg/s):
/// gravity on z, a lateral acceleration and a yaw rate that follow the
/// steering (v²·δ/L and v·δ/L of a 1.1 m wheelbase), plus the offsets.
#[must_use]
pub fn imu_truth(row: &Row) -> ([f64; 3], [f64; 3]) {
    let steer_rad = f64::from(row.steer_deg).to_radians();
    let v = f64::from(row.speed_mps);
    let lat_g = v * v * steer_rad / WHEELBASE_M / 9.81;
    let yaw_dps = (v * steer_rad / WHEELBASE_M).to_degrees();
    let accel = [0.0, lat_g, 1.0];
    let gyro = [0.0, 0.0, yaw_dps];
    (
        std::array::from_fn(|i| accel[i] + ACCEL_BIAS_G[i]),
        std::array::from_fn(|i| gyro[i] + GYRO_BIAS_DPS[i]),
    )
}

/// A bicycle-frame vector in the sensor's axes: the inverse of `map`
/// (a signed permutation, whose inverse is its transpose).
fn to_sensor(map: &AxisMap, bicycle: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|j| {
        let mut unit = [0.0f32; 3];
        unit[j] = 1.0;
        let column = map.apply(unit);
        (0..3).map(|i| f64::from(column[i]) * bicycle[i]).sum()
    })
}

/// The ADC reading (fractional counts) for `deg` under `cal`: the inverse
/// of its two- or three-point line.
#[must_use]
pub fn counts_for(cal: &SteeringCalibration, deg: f64) -> f64 {
    match cal.three_point {
        None => f64::from(cal.center_counts) + deg / f64::from(cal.deg_per_count),
        Some(points) => {
            let [a, b, c] = points.map(|p| (f64::from(p.counts), f64::from(p.deg)));
            // The segment on `deg`'s side of the middle point, extended
            // beyond the ends as the calibration extrapolates.
            let (p, q) = if (deg - b.1) * (a.1 - b.1) > 0.0 {
                (a, b)
            } else {
                (b, c)
            };
            p.0 + (deg - p.1) * (q.0 - p.0) / (q.1 - p.1)
        }
    }
}

/// The twelve data registers for one sample (big-endian words, accel then
/// gyro, sensor axes), from the bicycle-frame truth.
fn imu_registers(config: &Config, row: &Row, rng: &mut Rng) -> Vec<u8> {
    let scale = icm42688::Config::default().imu_config(config.imu);
    let (accel_g, gyro_dps) = imu_truth(row);
    let accel =
        to_sensor(&config.imu.axis_map, accel_g).map(|g| g / f64::from(scale.accel_g_per_lsb));
    let gyro =
        to_sensor(&config.imu.axis_map, gyro_dps).map(|d| d / f64::from(scale.gyro_dps_per_lsb));
    accel
        .iter()
        .chain(&gyro)
        .flat_map(|&lsb| {
            let noisy = (lsb + rng.range(-IMU_NOISE_LSB, IMU_NOISE_LSB)).round();
            (noisy.clamp(-32767.0, 32767.0) as i16).to_be_bytes()
        })
        .collect()
}

/// The frame's ADC conversions for `deg`: the reading dithered evenly
/// across one count, so their mean is within 1/(2·[`ADC_PER_FRAME`]) count
/// of the exact reading.
fn adc_conversions(cal: &SteeringCalibration, deg: f64) -> Vec<u16> {
    let exact = counts_for(cal, deg);
    (0..ADC_PER_FRAME)
        .map(|k| {
            let dither = (k as f64 + 0.5) / ADC_PER_FRAME as f64 - 0.5;
            (exact + dither).round().clamp(0.0, f64::from(cal.adc_max)) as u16
        })
        .collect()
}

/// Writes `ride.bin` for the first `frames` rows of `rows` (the last row
/// repeats if the ride is shorter), as a sensor mounted and calibrated as
/// `config` says produces it: IMU registers from [`imu_truth`] through the
/// inverse axis map with noise, ADC counts through the inverse steering
/// calibration. Wheel edges come from integrating the speed over the
/// firmware's wheel (its circumference and hole count).
///
/// # Errors
/// The file could not be written.
pub fn write_ride(
    path: &Path,
    rows: &[Row],
    frames: usize,
    config: &Config,
) -> std::io::Result<()> {
    let wheel = WheelConfig::DEFAULT;
    let pitch_m = f64::from(wheel.circumference_m) / f64::from(wheel.holes);
    let mut out = Vec::with_capacity(frames * 32);
    let mut rng = Rng::new(0x1A0);
    let mut distance_m = 0.0f64;
    let mut next_edge_m = pitch_m;
    let last = rows.last().copied().unwrap_or(Row {
        t_s: 0.0,
        steer_deg: 0.0,
        speed_mps: 0.0,
    });
    for k in 0..frames {
        let row = rows.get(k).copied().unwrap_or(last);
        out.extend(imu_registers(config, &row, &mut rng));
        let adc = adc_conversions(&config.steering, f64::from(row.steer_deg));
        out.push(adc.len() as u8);
        for c in adc {
            out.extend_from_slice(&c.to_le_bytes());
        }
        // Edges within this frame's 10 ms, as ages before the frame's end.
        let step_m = f64::from(row.speed_mps) * FRAME_US as f64 / 1e6;
        let mut ages = Vec::new();
        while next_edge_m <= distance_m + step_m && step_m > 0.0 {
            let frac = (next_edge_m - distance_m) / step_m;
            ages.push(((1.0 - frac) * FRAME_US as f64) as u16);
            next_edge_m += pitch_m;
        }
        distance_m += step_m;
        out.push(ages.len() as u8);
        for age in ages {
            out.extend_from_slice(&age.to_le_bytes());
        }
    }
    std::fs::write(path, out)
}

/// One chunk of GPS bytes and when its last byte arrives, µs since boot.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GpsChunk {
    /// Arrival time of the chunk's last byte, µs since boot.
    pub t_us: u64,
    /// The bytes.
    pub bytes: Vec<u8>,
}

/// The NMEA capture `fixtures/gps/NAME` scheduled as it was sent: each line
/// at its sentence's time of day relative to the first one (lines without a
/// time follow the previous one at UART pace), starting at `start_us`,
/// until `end_us`.
///
/// # Errors
/// The capture could not be read.
pub fn gps_schedule(name: &str, start_us: u64, end_us: u64) -> Result<Vec<GpsChunk>, String> {
    let path = gps_capture_path(name);
    let text = std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut chunks = Vec::new();
    let mut first_tod_ms: Option<u64> = None;
    let mut t_us = start_us;
    for line in text
        .split(|&b| b == b'\n')
        .filter(|l| !l.starts_with(b"#") && !l.is_empty())
    {
        if let Some(tod_ms) = time_of_day_ms(line) {
            let base = *first_tod_ms.get_or_insert(tod_ms);
            t_us = t_us.max(start_us + tod_ms.saturating_sub(base) * 1000);
        }
        let mut bytes = line.to_vec();
        bytes.push(b'\n');
        for piece in bytes.chunks(MAX_GPS_RECORD) {
            t_us += (piece.len() as f64 * CHAR_US) as u64;
            if t_us >= end_us {
                return Ok(chunks);
            }
            chunks.push(GpsChunk {
                t_us,
                bytes: piece.to_vec(),
            });
        }
    }
    Ok(chunks)
}

/// `hil-tests/fixtures/gps/NAME`.
#[must_use]
pub fn gps_capture_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join("gps")
        .join(name)
}

/// The time of day of an RMC, GGA, GLL or ZDA line, ms.
fn time_of_day_ms(line: &[u8]) -> Option<u64> {
    let text = std::str::from_utf8(line).ok()?;
    let mut fields = text.split(',');
    let kind = fields.next()?.get(3..)?;
    let field = match kind {
        "RMC" | "GGA" | "ZDA" => fields.next()?,
        "GLL" => fields.nth(4)?,
        _ => return None,
    };
    let hh: u64 = field.get(0..2)?.parse().ok()?;
    let mm: u64 = field.get(2..4)?.parse().ok()?;
    let secs: f64 = field.get(4..)?.parse().ok()?;
    Some((hh * 3600 + mm * 60) * 1000 + (secs * 1000.0).round() as u64)
}

/// Writes `gps.bin` (`t_ms` u32, `len` u16, bytes) for `chunks`.
///
/// # Errors
/// The file could not be written.
pub fn write_gps(path: &Path, chunks: &[GpsChunk]) -> std::io::Result<()> {
    let mut out = Vec::new();
    for c in chunks {
        let t_ms = u32::try_from(c.t_us / 1000).unwrap_or(u32::MAX);
        out.extend_from_slice(&t_ms.to_le_bytes());
        out.extend_from_slice(&(c.bytes.len() as u16).to_le_bytes());
        out.extend_from_slice(&c.bytes);
    }
    std::fs::write(path, out)
}

/// One position fix as gpsd reported it for a capture.
#[derive(Clone, Debug, PartialEq)]
pub struct GpsdFix {
    /// UTC, as gpsd writes it (`2020-03-18T13:28:20.600Z`).
    pub time: String,
    /// Latitude, degrees.
    pub lat_deg: f64,
    /// Longitude, degrees.
    pub lon_deg: f64,
}

/// gpsd's own decoding of capture `name`: every TPV report with a position
/// in its regression output (`NAME.chk` beside the capture), one per time
/// (gpsd reports an epoch again after each of its sentences).
///
/// # Errors
/// The file is missing or a report does not parse.
pub fn gpsd_fixes(name: &str) -> Result<Vec<GpsdFix>, String> {
    let path = gps_capture_path(&format!("{name}.chk"));
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out: Vec<GpsdFix> = Vec::new();
    for line in text.lines().filter(|l| l.starts_with('{')) {
        let v: serde_json::Value =
            serde_json::from_str(line).map_err(|e| format!("{}: {e}", path.display()))?;
        let (Some(time), Some(lat_deg), Some(lon_deg)) =
            (v["time"].as_str(), v["lat"].as_f64(), v["lon"].as_f64())
        else {
            continue;
        };
        if v["class"] == "TPV" && out.last().is_none_or(|f| f.time != time) {
            out.push(GpsdFix {
                time: time.to_owned(),
                lat_deg,
                lon_deg,
            });
        }
    }
    Ok(out)
}
