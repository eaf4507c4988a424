//! Export throughput: a one-hour 100 Hz log decoded to CSV and JSON lines.
//!
//! `cargo bench -p wobblog --bench export`; figures in `firmware/docs/benchmarks.md`.

use std::io::Write;
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use wobblog::cmd::{decode, encode};
use wobblog::export::Format;

const FRAMES_PER_HOUR: usize = 100 * 3600;

/// A one-hour ride as CSV: a 6.4 Hz steering wobble, speed and a GPS track.
fn one_hour_csv() -> Vec<u8> {
    let mut csv = Vec::with_capacity(FRAMES_PER_HOUR * 80);
    csv.extend_from_slice(
        b"t_s,ax_g,az_g,gz_dps,steer_deg,speed_mps,gps_lat_deg,gps_lon_deg,gps_speed_mps,gps_fix\n",
    );
    for i in 0..FRAMES_PER_HOUR {
        let t = i as f64 / 100.0;
        let steer = 2.0 * (t * 6.4 * std::f64::consts::TAU).sin();
        let lat = 52.2 + t * 1e-5;
        writeln!(
            csv,
            "{t},0.05,1.0,{:.3},{steer:.2},4.2,{lat:.7},6.88,4.2,3d",
            steer * 3.0
        )
        .unwrap();
    }
    csv
}

fn benches(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("wobblog-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let log = dir.join("hour.wbl");
    let file = std::fs::File::create(&log).unwrap();
    encode::encode(one_hour_csv().as_slice(), Path::new("hour.csv"), file, &log).unwrap();

    let mut group = c.benchmark_group("export");
    group.sample_size(10);
    group.throughput(Throughput::Elements(FRAMES_PER_HOUR as u64));
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
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(export, benches);
criterion_main!(export);
