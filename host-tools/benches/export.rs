//! Export throughput on a one-hour 100 Hz log (20 Hz GPS, a UTC sync pair
//! every 10 s, as the firmware writes): decoded to CSV and JSON lines, and
//! the `events` and `config` commands on it; `config` also on a 64 MiB log
//! of the same ride, which it must read no more of.
//!
//! `cargo bench -p wobblog --bench export`; figures in `firmware/docs/benchmarks.md`.

use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use wobble_core::config::Config;
use wobble_core::format::header::header_records;
use wobble_core::format::{
    quantise_i16, quantise_i32, BlockEncoder, FixMode, Frame, GpsFix, LogInfo, Record, UtcSync,
    UtcTime, EDGE_AGE_NONE, STEER_COUNTS_PER_DEG,
};
use wobblog::cmd::{config, decode, events};
use wobblog::export::Format;

const FRAMES_PER_HOUR: u64 = 100 * 3600;

/// A ride of `frames` frames: a 6.4 Hz steering wobble, speed, a GPS
/// track north.
fn ride_log(frames: u64) -> Vec<u8> {
    let mut bytes = Vec::new();
    let mut encoder = BlockEncoder::new();
    let mut put = |encoder: &mut BlockEncoder, rec: Record<'_>| {
        if let Some(block) = encoder.push(&rec).unwrap() {
            bytes.extend_from_slice(block);
        }
    };
    let mut config = String::new();
    Config::default().write_lines(&mut config).unwrap();
    let info = LogInfo {
        t_us: 0,
        firmware: "bench",
        device_id: [1; 12],
        sample_rate_hz: 100,
        run: 1,
    };
    for rec in header_records(info, config.lines()) {
        put(&mut encoder, rec);
    }
    for i in 0..frames {
        let t_us = i * 10_000;
        let t = t_us as f64 / 1e6;
        let steer = 2.0 * (t * 6.4 * std::f64::consts::TAU).sin();
        let frame = Frame {
            t_us,
            accel: [100, 0, 2048],
            gyro: [0, 0, quantise_i16(steer * 3.0, 32.0)],
            steer_cdeg: quantise_i16(steer, STEER_COUNTS_PER_DEG),
            wheel_count: 0,
            wheel_edge_age_us: EDGE_AGE_NONE,
            speed_mm_s: 4200,
            status: Default::default(),
        };
        put(&mut encoder, Record::Frame(frame));
        if i % 5 == 0 {
            let utc = UtcTime {
                days_since_2000: 7382,
                ms_of_day: 36_000_000 + (t_us / 1000) as u32,
            };
            let fix = GpsFix {
                t_us,
                utc: Some(utc),
                lat_e7: Some(quantise_i32(52.2 + t * 1e-5, 1e7)),
                lon_e7: Some(quantise_i32(6.88, 1e7)),
                speed_cm_s: Some(420),
                fix: FixMode::Fix3d,
                ..GpsFix::default()
            };
            put(&mut encoder, Record::Gps(fix));
            if i % 1000 == 0 {
                let sync = UtcSync {
                    t_us,
                    unix_ms: utc.unix_ms(),
                };
                put(&mut encoder, Record::UtcSync(sync));
            }
        }
    }
    if let Some(block) = encoder.finish() {
        bytes.extend_from_slice(block);
    }
    bytes
}

fn benches(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("wobblog-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let log = dir.join("hour.wbl");
    let hour = ride_log(FRAMES_PER_HOUR);
    std::fs::write(&log, &hour).unwrap();
    let big = dir.join("64mib.wbl");
    let big_frames = FRAMES_PER_HOUR * (64 << 20) / hour.len() as u64 + 1;
    std::fs::write(&big, ride_log(big_frames)).unwrap();

    let mut group = c.benchmark_group("export");
    group.sample_size(10);
    group.throughput(Throughput::Elements(FRAMES_PER_HOUR));
    for (name, format) in [
        ("csv_one_hour", Format::Csv),
        ("jsonl_one_hour", Format::Jsonl),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| {
                decode::decode_to(
                    &log,
                    &decode::Export::all(format),
                    std::io::sink(),
                    Path::new("sink"),
                )
                .unwrap()
            })
        });
    }
    group.bench_function("events_one_hour", |b| {
        b.iter(|| {
            events::list(&log, false, Vec::new(), std::io::sink())
                .unwrap()
                .unwrap()
        })
    });
    for (name, path) in [("config_one_hour", &log), ("config_64_mib", &big)] {
        group.bench_function(name, |b| {
            b.iter(|| config::read_header(path).unwrap().config_text(path))
        });
    }
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(export, benches);
criterion_main!(export);
