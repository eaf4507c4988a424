//! The wobble detector's cost per sample on the emulated Cortex-M4F: the
//! image runs the detector and the margin warning alone over the Figure-6
//! ride's steering and wheel speed, on QEMU's fixed instruction clock, and
//! reports the virtual time they took (`bench_detector` in the image). The
//! same on a ride with kicks: `qemu_kicks.rs`.

use std::path::Path;

use wobble_hil::qemu::{self, DetectorBench, Scenario};

const FRAMES: u32 = 3000;

#[test]
fn detector_cost_per_sample_on_the_cortex_m4() {
    let bundle = qemu::bundle(FRAMES).expect("fixtures");
    let dir = qemu::work_dir(Path::new(env!("CARGO_TARGET_TMPDIR")), "detector_cost").expect("dir");
    let scenario = Scenario {
        bench_detector: true,
        ..Scenario::ride(FRAMES)
    };
    let out = qemu::run(&bundle.setup(dir, scenario), |_| Ok(()), |_| {}).expect("qemu run");
    assert_eq!(out.code, 0, "{:?}", out.lines);
    let b = out.detector_bench().expect("BENCH line");
    assert_eq!(b.samples, u64::from(FRAMES));
    // The ride holds one wobble and no kick: the detector switched on and
    // off.
    assert_eq!((b.alert_changes, b.kicks), (2, 0), "{b:?}");
    println!(
        "FIGURES detector cost, ride without kicks: {} instructions per sample on average over {} \
         samples, {} on the worst (sample {})",
        b.mean, b.samples, b.worst, b.worst_at
    );
    assert!(b.mean > 0 && b.mean <= DetectorBench::MEAN_BUDGET, "{b:?}");
    assert!(b.worst <= DetectorBench::WORST_BUDGET, "{b:?}");
}
