//! Synthetic rides with everything known: roll, yaw, a wobble, GPS, an alert
//! and rider markers, written into card logs through the firmware's encoder.
//! Shared by the analysis, plot and export tests.
#![allow(dead_code)] // each test file uses part of it

use std::f64::consts::TAU;
use std::path::Path;

use assert_cmd::Command;
use wobble_core::format::header::header_records;
use wobble_core::format::{
    quantise_i16, quantise_i32, quantise_u16, Alert, BlockEncoder, FixMode, Frame, GpsFix,
    KickRingDown, LogInfo, Marker, Record, UtcSync, UtcTime, ACCEL_COUNTS_PER_G, EDGE_AGE_NONE,
    GYRO_COUNTS_PER_DPS, STEER_COUNTS_PER_DEG,
};
use wobblog::analysis::{Episode, Run};

/// The `wobblog` binary.
#[must_use]
pub fn wobblog() -> Command {
    Command::cargo_bin("wobblog").unwrap()
}

/// Runs `cmd`, which must succeed, and returns its standard output.
pub fn stdout_of(cmd: &mut Command) -> String {
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// `wobblog info --json` of `log`, which must succeed.
pub fn info_json(log: &Path) -> serde_json::Value {
    serde_json::from_str(&stdout_of(wobblog().arg("info").arg(log).arg("--json"))).unwrap()
}

/// A steady ride of `frames` 100 Hz frames (a 6.4 Hz steering sine at
/// 4 m/s with a GPS fix on every row) written as `csv_name` in `dir`, and the
/// log `wobblog encode` makes of it as `log_name`; returns both paths.
pub fn steady_ride_log(
    dir: &Path,
    frames: u32,
    csv_name: &str,
    log_name: &str,
) -> (std::path::PathBuf, std::path::PathBuf) {
    let mut csv =
        String::from("t_s,steer_deg,speed_mps,gps_lat_deg,gps_lon_deg,gps_speed_mps,gps_fix\n");
    for i in 0..frames {
        let t = f64::from(i) / 100.0;
        let steer = (t * 6.4 * TAU).sin();
        csv.push_str(&format!("{t},{steer:.2},4.0,52.2,6.88,4.0,3d\n"));
    }
    let csv_path = dir.join(csv_name);
    std::fs::write(&csv_path, csv).unwrap();
    let log = dir.join(log_name);
    wobblog()
        .args(["encode", "--csv"])
        .arg(&csv_path)
        .arg("-o")
        .arg(&log)
        .assert()
        .success();
    (csv_path, log)
}

/// How closely an episode is measured against its ground truth.
pub mod limits {
    /// The acceptance limits for a growing wobble...
    pub const FREQ_TOL_HZ: f64 = 0.1;
    pub const SIGMA_TOL_REL: f64 = 0.2;
    pub const ONSET_TOL_S: f64 = 0.2;
    pub const SPEED_TOL_MPS: f64 = 0.1;
    /// ...and for a kick's ring, looser: a ring decaying at 3-8/s lasts two
    /// or three cycles above the background.
    pub const KICK_FREQ_TOL_HZ: f64 = 0.5;
    pub const KICK_SIGMA_TOL_REL: f64 = 0.45;
}

/// The synthetic corpus: `hil-tests/fixtures/corpus`, or the
/// directory `CORPUS_DIR` names (e.g. a freshly generated one).
#[must_use]
pub fn corpus_dir() -> std::path::PathBuf {
    std::env::var_os("CORPUS_DIR").map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("../hil-tests/fixtures/corpus"),
        std::path::PathBuf::from,
    )
}

/// Standard gravity, m/s².
pub const G_MPS2: f64 = 9.806_65;
/// Height of the IMU on the rear rack above the ground, m.
pub const SENSOR_HEIGHT_M: f64 = 0.9;
/// Frame rate, Hz.
pub const FS_HZ: f64 = 100.0;

/// The wobble put into [`Ride::steer_deg`]: 7 Hz, growing at 2/s from
/// 0.02 degrees at 14 s to 2 degrees, then caught at 5/s.
pub mod wobble {
    /// Frequency, Hz.
    pub const FREQ_HZ: f64 = 7.0;
    /// Growth rate, 1/s.
    pub const SIGMA_PER_S: f64 = 2.0;
    /// Time the envelope is 0.02 degrees, s.
    pub const ONSET_S: f64 = 14.0;
    /// Largest envelope, degrees.
    pub const PEAK_DEG: f64 = 2.0;
    /// Decay after the peak, 1/s.
    pub const DECAY_PER_S: f64 = 5.0;

    /// Time of the peak, s.
    #[must_use]
    pub fn peak_s() -> f64 {
        ONSET_S + (PEAK_DEG / 0.02).ln() / SIGMA_PER_S
    }

    /// Envelope at `t`, degrees.
    #[must_use]
    pub fn envelope_deg(t: f64) -> f64 {
        if t < peak_s() {
            0.02 * (SIGMA_PER_S * (t - ONSET_S)).exp()
        } else {
            PEAK_DEG * (-DECAY_PER_S * (t - peak_s())).exp()
        }
    }
}

/// A ride's true signals, one entry per frame.
#[derive(Clone, Debug, Default)]
pub struct Ride {
    /// s since boot.
    pub t_s: Vec<f64>,
    /// True roll, degrees, positive leaning right.
    pub roll_deg: Vec<f64>,
    /// Steering angle, degrees.
    pub steer_deg: Vec<f64>,
    /// m/s.
    pub speed_mps: Vec<f64>,
    /// What the IMU measures (with the given gyro bias), deg/s.
    pub gyro_dps: Vec<[f64; 3]>,
    /// What the IMU measures, g.
    pub accel_g: Vec<[f64; 3]>,
}

/// Roll of the synthetic ride at `t`, radians, and its first two
/// derivatives: corners of ±`corner_deg` (raised cosines, 5 s each, every
/// 12 s) and a 1 Hz weave of `weave_deg`.
fn roll_at(t: f64, corner_deg: f64, weave_deg: f64) -> [f64; 3] {
    let (period_s, corner_s) = (12.0, 5.0);
    let k = (t / period_s).floor();
    let u = t - k * period_s;
    let sign = if (k as i64) % 2 == 0 { 1.0 } else { -1.0 };
    let a = sign * corner_deg.to_radians() * 0.5;
    let w = TAU / corner_s;
    let corner = if u < corner_s {
        [
            a * (1.0 - (w * u).cos()),
            a * w * (w * u).sin(),
            a * w * w * (w * u).cos(),
        ]
    } else {
        [0.0; 3]
    };
    let wv = TAU * 1.0;
    let b = weave_deg.to_radians();
    let weave = [
        b * (wv * t).sin(),
        b * wv * (wv * t).cos(),
        -b * wv * wv * (wv * t).sin(),
    ];
    [
        corner[0] + weave[0],
        corner[1] + weave[1],
        corner[2] + weave[2],
    ]
}

impl Ride {
    /// A ride of `duration_s` at `speed_mps` with corners of `corner_deg`
    /// lean, a weave of `weave_deg`, a roll gyro biased by `gyro_bias_dps`,
    /// the lean balanced by the turn at every instant, and the wobble of
    /// [`wobble`] in the steering.
    #[must_use]
    pub fn new(
        duration_s: f64,
        speed_mps: f64,
        corner_deg: f64,
        weave_deg: f64,
        gyro_bias_dps: f64,
    ) -> Self {
        let mut ride = Self::default();
        let n = (duration_s * FS_HZ).round() as usize;
        for i in 0..n {
            let t = 1.0 + i as f64 / FS_HZ;
            let [phi, phi_dot, phi_ddot] = roll_at(t, corner_deg, weave_deg);
            // Leaning right (phi > 0) turns right: yaw rate negative about z up.
            let yaw_rate = -G_MPS2 * phi.tan() / speed_mps;
            let a_c = speed_mps * yaw_rate;
            let h = SENSOR_HEIGHT_M;
            let fy = a_c * phi.cos() + G_MPS2 * phi.sin() - h * phi_ddot;
            let fz = -a_c * phi.sin() + G_MPS2 * phi.cos() - h * phi_dot * phi_dot;
            ride.t_s.push(t);
            ride.roll_deg.push(phi.to_degrees());
            ride.steer_deg
                .push(2.0 * phi + wobble::envelope_deg(t) * (TAU * wobble::FREQ_HZ * t).sin());
            ride.speed_mps.push(speed_mps);
            ride.gyro_dps.push([
                phi_dot.to_degrees() + gyro_bias_dps,
                (yaw_rate * phi.sin()).to_degrees(),
                (yaw_rate * phi.cos()).to_degrees(),
            ]);
            ride.accel_g.push([0.0, fy / G_MPS2, fz / G_MPS2]);
        }
        ride
    }

    /// The ride as the analysis sees it, without going through a log.
    #[must_use]
    pub fn run(&self) -> Run {
        Run {
            t_s: self.t_s.clone(),
            steer_deg: self.steer_deg.clone(),
            speed_mps: self.speed_mps.clone(),
            gyro_dps: self.gyro_dps.clone(),
            accel_g: self.accel_g.clone(),
            ..Run::default()
        }
    }
}

/// What [`write_log`] adds around the frames.
#[derive(Clone, Debug, Default)]
pub struct Extras {
    /// Alert periods, s.
    pub alerts_s: Vec<(f64, f64)>,
    /// Rider markers, s.
    pub markers_s: Vec<f64>,
    /// GPS fixes at 20 Hz along a straight line due north, except in these
    /// spans (no fix), s.
    pub gps_outages_s: Vec<(f64, f64)>,
    /// Whether to write GPS at all.
    pub gps: bool,
    /// Records written after the frame at their time (faults, dropouts, ...).
    pub records: Vec<Record<'static>>,
    /// Configuration lines for the header.
    pub config: Vec<String>,
}

/// How often [`write_log`] writes a UTC sync pair, µs.
pub const SYNC_INTERVAL_US: u64 = 10_000_000;
/// UTC of the fixes at 0 s since boot: 2020-03-18T10:00:00Z, ms since 1970.
pub const UTC_AT_BOOT_MS: i64 = 1_584_525_600_000;

/// Latitude of the GPS track's start, degrees.
pub const START_LAT_DEG: f64 = 52.2;
/// Longitude of the GPS track, degrees.
pub const LON_DEG: f64 = 6.88;

/// The GPS fix at frame `i` of `ride` if one is due (every 5th frame).
pub fn gps_fix(ride: &Ride, i: usize, extras: &Extras) -> Option<GpsFix> {
    let t = ride.t_s[i];
    if !extras.gps || i.rem_euclid(5) > 0 {
        return None;
    }
    let t_us = (t * 1e6).round() as u64;
    if extras
        .gps_outages_s
        .iter()
        .any(|&(a, b)| (a..b).contains(&t))
    {
        return Some(GpsFix {
            t_us,
            ..GpsFix::default()
        });
    }
    let north_m = ride.speed_mps[i] * (t - ride.t_s[0]);
    Some(GpsFix {
        t_us,
        utc: Some(UtcTime {
            days_since_2000: 7382,
            ms_of_day: 36_000_000 + (t * 1000.0).round() as u32,
        }),
        lat_e7: Some(quantise_i32(START_LAT_DEG + north_m / 111_320.0, 1e7)),
        lon_e7: Some(quantise_i32(LON_DEG, 1e7)),
        speed_cm_s: Some(quantise_u16(ride.speed_mps[i], 100.0)),
        alt_cm: Some(4210),
        fix: FixMode::Fix3d,
        sats: Some(9),
        hdop_d: Some(8),
        ..GpsFix::default()
    })
}

/// Writes `ride` and `extras` as a card log at `path`.
pub fn write_log(path: &Path, ride: &Ride, extras: &Extras) {
    let mut bytes = Vec::new();
    let mut encoder = BlockEncoder::new();
    let mut put = |encoder: &mut BlockEncoder, rec: Record<'_>| {
        if let Some(block) = encoder.push(&rec).unwrap() {
            bytes.extend_from_slice(block);
        }
    };
    let t_us = |t: f64| (t * 1e6).round() as u64;
    let info = LogInfo {
        t_us: t_us(ride.t_s[0]),
        firmware: "test",
        device_id: [7; 12],
        sample_rate_hz: 100,
        run: 3,
    };
    for rec in header_records(info, extras.config.iter().map(String::as_str)) {
        put(&mut encoder, rec);
    }
    let mut last_sync_us: Option<u64> = None;
    for i in 0..ride.t_s.len() {
        let t = ride.t_s[i];
        let frame = Frame {
            t_us: t_us(t),
            accel: ride.accel_g[i].map(|v| quantise_i16(v, ACCEL_COUNTS_PER_G)),
            gyro: ride.gyro_dps[i].map(|v| quantise_i16(v, GYRO_COUNTS_PER_DPS)),
            steer_cdeg: quantise_i16(ride.steer_deg[i], STEER_COUNTS_PER_DEG),
            wheel_count: 0,
            wheel_edge_age_us: EDGE_AGE_NONE,
            speed_mm_s: quantise_u16(ride.speed_mps[i], 1000.0),
            status: Default::default(),
        };
        put(&mut encoder, Record::Frame(frame));
        if let Some(fix) = gps_fix(ride, i, extras) {
            put(&mut encoder, Record::Gps(fix));
            // A sync pair with the first fix with UTC, then every 10 s, as
            // the firmware's GPS path writes them.
            if let Some(utc) = fix.utc {
                if last_sync_us.is_none_or(|last| fix.t_us - last >= SYNC_INTERVAL_US) {
                    last_sync_us = Some(fix.t_us);
                    let unix_ms = utc.unix_ms();
                    put(
                        &mut encoder,
                        Record::UtcSync(UtcSync {
                            t_us: fix.t_us,
                            unix_ms,
                        }),
                    );
                }
            }
        }
        let now = |s: f64| (s - t).abs() < 0.5 / FS_HZ;
        for &(on, off) in &extras.alerts_s {
            for (at, is_on) in [(on, true), (off, false)] {
                if now(at) {
                    let alert = Alert {
                        t_us: t_us(t),
                        on: is_on,
                        freq_chz: if is_on { 700 } else { 0 },
                        amp_cdeg: if is_on { 80 } else { 0 },
                    };
                    put(&mut encoder, Record::Alert(alert));
                }
            }
        }
        for rec in &extras.records {
            if now(rec.t_us() as f64 / 1e6) {
                put(&mut encoder, *rec);
            }
        }
        for (id, &m) in extras.markers_s.iter().enumerate() {
            if now(m) {
                put(
                    &mut encoder,
                    Record::Marker(Marker {
                        t_us: t_us(t),
                        id: id as u16,
                    }),
                );
            }
        }
    }
    if let Some(block) = encoder.finish() {
        bytes.extend_from_slice(block);
    }
    std::fs::write(path, bytes).unwrap();
}

/// A 30 s ride (corners of 15 degrees, weave, the wobble) with GPS, an
/// alert from 16 to 17.5 s and markers at 5 and 20 s, written to `path`.
pub fn standard_log(path: &Path) -> (Ride, Extras) {
    let ride = Ride::new(30.0, 5.0, 15.0, 2.0, 0.5);
    let extras = Extras {
        alerts_s: vec![(16.0, 17.5)],
        markers_s: vec![5.0, 20.0],
        gps_outages_s: vec![(22.0, 29.0)],
        gps: true,
        ..Extras::default()
    };
    write_log(path, &ride, &extras);
    (ride, extras)
}

/// A 20 s ride from 1 s since boot whose GPS has no fix before 5 s: 400
/// rows with empty GPS cells first, as on every real ride.
pub fn late_fix_log(path: &Path) {
    let ride = Ride::new(20.0, 5.0, 0.0, 0.0, 0.0);
    let extras = Extras {
        gps: true,
        gps_outages_s: vec![(0.0, 5.0)],
        ..Extras::default()
    };
    write_log(path, &ride, &extras);
}

/// `wobblog decode LOG -o OUT EXTRA...`, run to its end, whatever its exit.
pub fn decode_to(log: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    wobblog()
        .arg("decode")
        .arg(log)
        .arg("-o")
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

/// `a` and `b` measure the same episode: every value to 1e-9, the same
/// stability and cuts.
pub fn assert_same_episode(a: &Episode, b: &Episode) {
    let pairs = [
        (a.onset_s, b.onset_s),
        (a.end_s, b.end_s),
        (a.peak_s, b.peak_s),
        (a.freq_hz, b.freq_hz),
        (a.sigma_per_s, b.sigma_per_s),
        (a.peak_amp_deg, b.peak_amp_deg),
        (a.speed_at_onset_mps, b.speed_at_onset_mps),
    ];
    for (x, y) in pairs {
        assert!((x - y).abs() <= 1e-9 * x.abs().max(1.0), "{a:?}\n{b:?}");
    }
    assert_eq!(a.stability, b.stability);
    assert_eq!(
        (a.cut_at_start, a.cut_at_end),
        (b.cut_at_start, b.cut_at_end)
    );
}

/// Runs the Python `script` with `args` and parses what it prints as JSON:
/// outputs read back by the tools researchers use (Polars, pyarrow,
/// pandas, DuckDB, gpxpy). `None` when a package is missing outside CI;
/// under CI (`CI=true`) a missing package fails the test, so a green run
/// never hides a skipped check (`hil-tests/install-tools.sh` installs them).
pub fn python(script: &str, args: &[&std::ffi::OsStr]) -> Option<serde_json::Value> {
    let out = std::process::Command::new("python3")
        .arg("-c")
        .arg(script)
        .args(args)
        .output()
        .expect("python3 runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    if let Some(at) = stderr.find("No module named") {
        let missing = stderr[at..].lines().next().unwrap_or_default();
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "{missing}: hil-tests/install-tools.sh installs the Python packages the tests read outputs with"
        );
        eprintln!("SKIPPED: {missing} (hil-tests/install-tools.sh installs it)");
        return None;
    }
    assert!(out.status.success(), "{stderr}");
    Some(serde_json::from_slice(&out.stdout).expect("the script prints JSON"))
}

/// A 10 s pass at `speed` with one kick at 3 s: a 0.1 s push of 4 degrees,
/// then a ring of 1.5 degrees at `freq_hz` decaying at
/// `0.5 (speed - wobble_mps)`, plus a weave and small deterministic noise
/// (`seed`): one pass of a kick campaign whose wobble speed is
/// `wobble_mps`.
#[must_use]
pub fn kick_pass(speed: f64, wobble_mps: f64, freq_hz: f64, seed: u32) -> Ride {
    let mut ride = Ride::new(10.0, speed, 0.0, 0.5, 0.0);
    let sigma = 0.5 * (speed - wobble_mps);
    let mut state = 0x9E37_79B9u32 ^ seed;
    for (t, s) in ride.t_s.iter().zip(ride.steer_deg.iter_mut()) {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        let noise = 0.02 * (f64::from(state) / f64::from(u32::MAX) - 0.5);
        let tau = t - 3.0;
        let push = if (0.0..0.1).contains(&tau) {
            4.0 * (TAU / 0.2 * tau).sin()
        } else {
            0.0
        };
        let ring = if tau >= 0.1 {
            1.5 * (sigma * (tau - 0.1)).exp() * (TAU * freq_hz * (tau - 0.1)).sin()
        } else {
            0.0
        };
        *s += push + ring + noise;
    }
    ride
}

/// A card record of a kick at `t_s` (6.9 Hz, sigma -1.1 +- 0.05 1/s),
/// with the speed the board measured, if any.
pub fn kick_record(t_s: f64, speed_mm_s: Option<u16>) -> Record<'static> {
    Record::Kick(KickRingDown {
        t_us: (t_s * 1e6).round() as u64,
        speed_mm_s,
        freq_chz: 690,
        sigma_milli_per_s: -1100,
        sigma_se_milli_per_s: 50,
        amp_cdeg: 140,
        segments: 9,
    })
}
