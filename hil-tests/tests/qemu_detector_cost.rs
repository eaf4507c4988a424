//! The wobble detector's cost per sample on the emulated Cortex-M4F: the
//! image runs the detector alone over the Figure-6 ride's steering, on
//! QEMU's fixed instruction clock, and reports the virtual time it took.

use std::path::Path;

use wobble_hil::qemu::{self, Scenario, ICOUNT_SHIFT};

const FRAMES: u32 = 3000;
/// A 10 ms frame at 168 MHz is 1.68 M cycles; the detector may take at most
/// 1 % of it on average.
const BUDGET_INSTRUCTIONS_PER_SAMPLE: u64 = 16_800;

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
    let samples = out.number("BENCH", "samples").expect("BENCH line");
    let us = out.number("BENCH", "us").expect("BENCH line");
    assert_eq!(samples, u64::from(FRAMES));
    // The ride holds one wobble: the detector switched on and off.
    assert_eq!(out.number("BENCH", "alert_changes"), Some(2));
    let ns_per_instruction = 1u64 << ICOUNT_SHIFT;
    let per_sample = us * 1000 / ns_per_instruction / samples;
    println!(
        "FIGURES detector cost: {per_sample} instructions per sample on average over {samples} \
         samples ({us} µs virtual at {ns_per_instruction} ns per instruction)"
    );
    assert!(per_sample > 0 && per_sample <= BUDGET_INSTRUCTIONS_PER_SAMPLE);
}
