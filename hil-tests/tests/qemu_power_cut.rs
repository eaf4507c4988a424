//! Power cuts at 100 different block writes: whatever the moment, the card
//! keeps every frame up to the last flush, loses at most one flush period,
//! and its file system is at worst in the documented state of an unclosed
//! file.

use std::path::Path;

use wobble_core::logger::LoggerConfig;
use wobble_hil::corpus::rng::Rng;
use wobble_hil::qemu::{self, decode, Scenario};

/// 12 s rides: about 14 block writes a second (data, flush snapshots, FAT
/// and directory updates), so every cut in 1..=MAX_CUT_WRITE happens.
const FRAMES: u32 = 1200;
/// Highest block write a cut is put before.
const MAX_CUT_WRITE: u32 = 150;
const CUTS: usize = 100;
/// Frames a flush period holds.
const FLUSH_FRAMES: u64 = LoggerConfig::DEFAULT.flush_period_ms as u64 / 10;
/// Records waiting in the queue at the cut (not yet handed to the logger).
const QUEUE_SLACK_FRAMES: u64 = 3;

#[test]
fn power_cut_at_100_random_block_writes() {
    let bundle = qemu::bundle(FRAMES).expect("fixtures");
    let mut rng = Rng::new(0xC07);
    let mut cuts: Vec<u32> = Vec::new();
    while cuts.len() < CUTS {
        let w = rng.range(1.0, f64::from(MAX_CUT_WRITE) + 1.0) as u32;
        if !cuts.contains(&w) {
            cuts.push(w);
        }
    }
    let base = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let results: Vec<(u32, u64, u64)> = std::thread::scope(|s| {
        let workers: Vec<_> = cuts
            .chunks(CUTS / 2)
            .map(|chunk| {
                let bundle = &bundle;
                s.spawn(move || {
                    chunk
                        .iter()
                        .map(|&w| one_cut(bundle, base, w))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|h| h.join().expect("worker"))
            .collect()
    });
    let worst = results.iter().map(|r| r.1 - r.2).max().unwrap_or(0);
    let mean = results.iter().map(|r| (r.1 - r.2) as f64).sum::<f64>() / results.len() as f64;
    println!("FIGURES power cut: {} cuts, frames lost per cut mean {mean:.1}, worst {worst} (flush period {FLUSH_FRAMES} frames)", results.len());
}

/// Runs one cut before block write `write`; returns (write, frames sampled,
/// frames on card).
fn one_cut(bundle: &qemu::Bundle, base: &Path, write: u32) -> (u32, u64, u64) {
    let dir = qemu::work_dir(base, &format!("cut{write:03}")).expect("dir");
    let scenario = Scenario {
        cut_at_write: Some(write),
        ..Scenario::ride(FRAMES)
    };
    let out =
        qemu::run(&bundle.setup(dir.clone(), scenario), |_| Ok(()), |_| {}).expect("qemu run");
    assert_eq!(
        out.code, 3,
        "cut at write {write} happened: {:?}",
        out.lines
    );
    let sampled = out.number("CUT", "frames").expect("CUT line");
    let fsck = qemu::card::fsck(&out.card).expect("fsck");
    let worse: Vec<_> = fsck
        .problems()
        .into_iter()
        .filter(|p| !qemu::is_unclosed_file_state(p))
        .collect();
    assert!(worse.is_empty(), "cut at write {write}: {}", fsck.text);
    let logs = match decode::logs(&out.card, &dir) {
        Ok(logs) => logs,
        // No valid block yet: the cut came before the first flush.
        Err(e) if e.contains("RUN00001.WBL") => Vec::new(),
        Err(e) => panic!("cut at write {write}: {e}"),
    };
    let frames: Vec<u64> = logs
        .iter()
        .flat_map(|l| l.frames.iter().map(|f| f.t_us))
        .collect();
    // Exactly a prefix of the ride, 10 ms apart, nothing damaged.
    for (k, &t_us) in frames.iter().enumerate() {
        assert_eq!(
            out.frame_index(t_us),
            k as u64,
            "cut at write {write}: frame {k}"
        );
    }
    assert!(logs
        .iter()
        .all(|l| l.stats.damaged_blocks == 0 && l.dropouts.is_empty()));
    let on_card = frames.len() as u64;
    assert!(
        sampled - on_card <= FLUSH_FRAMES + QUEUE_SLACK_FRAMES,
        "cut at write {write}: {on_card} of {sampled} frames kept"
    );
    (write, sampled, on_card)
}
