//! Host timing of the detector (criterion): nanoseconds per 100 Hz sample over
//! a 30 s fixture. The firmware figure is the analytical count in
//! `DetectorConfig::cost` (see `firmware/docs/detector.md`); this bench is the
//! host-side criterion until a QEMU instruction count replaces it.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use wobble_core::config::Config;
use wobble_hil::corpus;

fn bench(c: &mut Criterion) {
    let fixtures = corpus::generate();
    let Some(fx) = fixtures.iter().find(|f| f.truth.name == "wobble_fig6") else {
        return;
    };
    let Ok(rows) = fx.rows() else { return };
    let mut g = c.benchmark_group("detector");
    g.throughput(Throughput::Elements(rows.len() as u64));
    g.bench_function("push_30s_fig6", |b| {
        b.iter(|| {
            let Ok(mut det) = Config::default().detector() else {
                return 0;
            };
            let mut n = 0;
            for r in &rows {
                if det
                    .push(black_box(r.steer_deg), Some(r.speed_mps))
                    .is_some()
                {
                    n += 1;
                }
            }
            n
        });
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
