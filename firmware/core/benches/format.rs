//! Card-format throughput: encoding frames, decoding a one-hour log,
//! resynchronising through floods of sync markers.
//!
//! `cargo bench -p wobble-core --bench format`; figures in `firmware/docs/benchmarks.md`.

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use std::hint::black_box;
use wobble_core::format::*;

const FRAMES_PER_HOUR: u64 = 100 * 3600;

/// A ride's records: 100 Hz frames with varying values, a 20 Hz GPS fix
/// stamped a little before the frame it follows.
fn ride(frames: u64) -> impl Iterator<Item = Record<'static>> {
    (0..frames).flat_map(|i| {
        let t_us = 1_000_000 + i * 10_000 + (i * 7919) % 40;
        let wave = |k: u64, amp: i64| ((i * k) % 200) as i64 * amp / 100 - amp;
        let frame = Frame {
            t_us,
            accel: [
                wave(3, 300) as i16,
                wave(5, 200) as i16,
                2048 + wave(7, 100) as i16,
            ],
            gyro: [
                wave(11, 900) as i16,
                wave(13, 600) as i16,
                wave(17, 1200) as i16,
            ],
            steer_cdeg: wave(19, 500) as i16,
            wheel_count: (i * 9 / 10) as u16,
            wheel_edge_age_us: (i % 11_000) as u16,
            speed_mm_s: 4000 + wave(1, 500) as u16,
            status: FrameStatus(0),
        };
        let gps = (i % 5 == 0).then(|| {
            Record::Gps(GpsFix {
                t_us: t_us - 3_000,
                utc: Some(UtcTime {
                    days_since_2000: 7382,
                    ms_of_day: (i * 10) as u32,
                }),
                lat_e7: Some(522_100_000 + i as i32),
                lon_e7: Some(68_800_000 - i as i32),
                speed_cm_s: Some(400),
                course_cdeg: Some(9_000),
                alt_cm: Some(3_000),
                fix: FixMode::Fix3d,
                sats: Some(11),
                hdop_d: Some(8),
            })
        });
        core::iter::once(Record::Frame(frame)).chain(gps)
    })
}

fn encode_log(frames: u64) -> Vec<u8> {
    let mut enc = BlockEncoder::new();
    let mut file = Vec::new();
    for rec in ride(frames) {
        if let Some(block) = enc.push(&rec).expect("encodable") {
            file.extend_from_slice(block);
        }
    }
    if let Some(block) = enc.finish() {
        file.extend_from_slice(block);
    }
    file
}

fn decode(log: &[u8]) -> u64 {
    let mut dec = Decoder::new();
    let mut frames = 0u64;
    dec.feed(log, true, &mut |e| {
        if let Event::Record(Record::Frame(f)) = e {
            frames += u64::from(black_box(f).speed_mm_s > 0);
        }
    });
    frames
}

fn benches(c: &mut Criterion) {
    let log = encode_log(FRAMES_PER_HOUR);
    println!(
        "one-hour log: {} bytes, {:.2} bytes per frame (20 Hz GPS and block overhead included)",
        log.len(),
        log.len() as f64 / FRAMES_PER_HOUR as f64
    );
    let mut group = c.benchmark_group("format");
    group.sample_size(20);
    group.throughput(Throughput::Bytes(log.len() as u64));
    group.bench_function("decode_one_hour_bytes", |b| {
        b.iter(|| decode(black_box(&log)))
    });
    group.throughput(Throughput::Elements(FRAMES_PER_HOUR));
    group.bench_function("decode_one_hour_frames", |b| {
        b.iter(|| decode(black_box(&log)))
    });
    group.bench_function("encode_one_hour_frames", |b| {
        b.iter_batched(
            || (),
            |()| encode_log(FRAMES_PER_HOUR),
            BatchSize::SmallInput,
        )
    });
    // Resynchronising through 4 MiB of sync markers: bare, and 8 bytes
    // apart with fields that pass (every one checked by its CRC).
    for (name, pattern) in [
        ("scan_marker_flood_4mib", &b"WBLK"[..]),
        ("scan_candidate_flood_4mib", &b"WBLK\x01\x00\xe4\x01"[..]),
    ] {
        let flood = pattern.repeat((4 << 20) / pattern.len());
        group.throughput(Throughput::Bytes(flood.len() as u64));
        group.bench_function(name, |b| b.iter(|| decode(black_box(&flood))));
    }
    group.finish();
}

criterion_group!(format, benches);
criterion_main!(format);
