//! Power cuts at 100 different block writes, and inside 40 more while the
//! card is busy with them (the card model takes the SD specification's
//! times, so a cut can land while a block is being programmed and leave it
//! torn): whatever the moment, the card keeps every frame up to the last
//! flush except those of the one block the cut hit, which the decoder
//! reports, loses at most one flush period plus what queued behind a busy
//! card, and its file system is at worst in the documented state of an
//! unclosed file. Every cut's card also holds an earlier ride, which must
//! come back whole: the logger rewrites the sectors it shares with it (the
//! root directory's, FSInfo, the FAT's) seldom, and a cut during one of
//! those writes leaves its other entries as they were.

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
/// The first block writes of a ride, each cut before.
const OPENING_WRITES: u32 = 24;
/// Frames a flush period holds.
const FLUSH_FRAMES: u64 = LoggerConfig::DEFAULT.flush_period_ms as u64 / 10;
/// Records waiting in the queue at the cut (not yet handed to the logger):
/// a few, plus those queued while the card was busy with a block, up to the
/// SD specification's 250 ms.
const QUEUE_SLACK_FRAMES: u64 = 3 + 25;
/// Cuts inside block writes.
const TORN_CUTS: usize = 40;

#[test]
fn power_cut_at_100_random_block_writes() {
    let bundle = qemu::bundle(FRAMES).expect("fixtures");
    let mut rng = Rng::new(0xC07);
    // Every write of the file's opening (its entry, the FAT, FSInfo, the
    // header, the first flushes), then random ones.
    let mut cuts: Vec<u32> = (1..=OPENING_WRITES).collect();
    while cuts.len() < CUTS {
        let w = rng.range(1.0, f64::from(MAX_CUT_WRITE) + 1.0) as u32;
        if !cuts.contains(&w) {
            cuts.push(w);
        }
    }
    let base = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let results = on_two_workers(&cuts, |&w| one_cut(&bundle, base, w));
    let worst = results.iter().map(|r| r.1 - r.2).max().unwrap_or(0);
    let mean = results.iter().map(|r| (r.1 - r.2) as f64).sum::<f64>() / results.len() as f64;
    println!("FIGURES power cut: {} cuts, frames lost per cut mean {mean:.1}, worst {worst} (flush period {FLUSH_FRAMES} frames)", results.len());
}

/// `run` over `items` on two threads (QEMU runs one core each), results in
/// the order of `items`.
fn on_two_workers<T: Sync, R: Send>(items: &[T], run: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let run = &run;
    std::thread::scope(|s| {
        let workers: Vec<_> = items
            .chunks(items.len().div_ceil(2).max(1))
            .map(|chunk| s.spawn(move || chunk.iter().map(run).collect::<Vec<_>>()))
            .collect();
        workers
            .into_iter()
            .flat_map(|h| h.join().expect("worker"))
            .collect()
    })
}

/// Frames of the earlier ride on the card.
const EARLIER_FRAMES: u64 = 3_000;

/// An earlier ride of 30 s as the card holds it (frames only).
fn earlier_ride() -> Vec<u8> {
    use wobble_core::format::{BlockEncoder, Frame, FrameStatus, Record};
    let mut encoder = BlockEncoder::new();
    let mut bytes = Vec::new();
    for i in 0..EARLIER_FRAMES {
        let frame = Record::Frame(Frame {
            t_us: i * 10_000,
            accel: [(i % 700) as i16, 0, 2048],
            gyro: [0, (i % 50) as i16, 0],
            steer_cdeg: (i % 500) as i16,
            wheel_count: i as u16,
            wheel_edge_age_us: 100,
            speed_mm_s: 3000,
            status: FrameStatus(0),
        });
        if let Some(block) = encoder.push(&frame).expect("encode") {
            bytes.extend_from_slice(block);
        }
    }
    bytes.extend_from_slice(encoder.snapshot().expect("open block"));
    bytes
}

/// Runs one cut before block write `write`; returns (write, frames sampled,
/// frames on card).
fn one_cut(bundle: &qemu::Bundle, base: &Path, write: u32) -> (u32, u64, u64) {
    let scenario = Scenario {
        cut_at_write: Some(write),
        ..Scenario::ride(FRAMES)
    };
    let cut = cut_run(bundle, base, &format!("cut{write:03}"), scenario);
    assert_eq!(cut.damaged, 0, "cut before write {write}: no block damaged");
    assert_eq!(cut.torn, 0);
    (write, cut.sampled, cut.frames.len() as u64)
}

/// Runs one cut `permille` thousandths into block write `write`; returns
/// (frames sampled, frames on card, bytes of the block programmed, damaged
/// blocks).
fn one_torn_cut(
    bundle: &qemu::Bundle,
    base: &Path,
    write: u32,
    permille: u32,
) -> (u64, u64, u64, u64) {
    let scenario = Scenario {
        cut_in_write: Some((write, permille)),
        ..Scenario::ride(FRAMES)
    };
    let cut = cut_run(bundle, base, &format!("torn{write:03}"), scenario);
    // Only a block the card had begun programming can be damaged, and only
    // that one.
    assert!(
        cut.damaged <= u64::from(cut.torn > 0),
        "cut {permille}/1000 into write {write}: {} damaged blocks, {} bytes programmed",
        cut.damaged,
        cut.torn
    );
    (cut.sampled, cut.frames.len() as u64, cut.torn, cut.damaged)
}

/// What a cut left.
struct Cut {
    /// Frames the sampler had taken.
    sampled: u64,
    /// Frame indices on the card, in file order.
    frames: Vec<u64>,
    /// Damaged blocks the decoder skipped.
    damaged: u64,
    /// Bytes of the cut block the card had programmed.
    torn: u64,
}

/// Runs `scenario` (one power cut) and checks what every cut must leave:
/// the frames on the card are the ride's in order, with a gap only where
/// the decoder reports a damaged block, no more lost than a flush period
/// plus the queue, and the file system at worst unclosed.
fn cut_run(bundle: &qemu::Bundle, base: &Path, name: &str, scenario: Scenario) -> Cut {
    let dir = qemu::work_dir(base, name).expect("dir");
    let earlier = earlier_ride();
    let out = qemu::run(
        &bundle.setup(dir.clone(), scenario),
        |card| qemu::card::put_file(card, "RUN00001.WBL", &earlier),
        |_| {},
    )
    .expect("qemu run");
    assert_eq!(out.code, 3, "{name}: the cut happened: {:?}", out.lines);
    let sampled = out.number("CUT", "frames").expect("CUT line");
    let fsck = qemu::card::fsck(&out.card).expect("fsck");
    let worse: Vec<_> = fsck
        .problems()
        .into_iter()
        .filter(|p| !qemu::is_unclosed_file_state(p))
        .collect();
    assert!(worse.is_empty(), "{name}: {}", fsck.text);
    // The earlier ride byte for byte.
    let files = qemu::card::root_files(&out.card).expect("files");
    let kept = files.iter().find(|(file, _)| file == "RUN00001.WBL");
    assert_eq!(
        kept.map(|k| &k.1),
        Some(&earlier),
        "{name}: the earlier ride"
    );
    let logs = match decode::logs(&out.card, &dir) {
        Ok(logs) => logs,
        // No valid block yet: the cut came before the first flush.
        Err(e) if e.contains("RUN00002.WBL") => Vec::new(),
        Err(e) => panic!("{name}: {e}"),
    };
    let logs: Vec<_> = logs
        .into_iter()
        .filter(|l| l.name != "RUN00001.WBL")
        .collect();
    let frames: Vec<u64> = logs
        .iter()
        .flat_map(|l| l.frames.iter().map(|f| out.frame_index(f.t_us)))
        .collect();
    let damaged: u64 = logs.iter().map(|l| l.stats.damaged_blocks).sum();
    let torn = out.number("CUT", "torn").expect("CUT line");
    // A prefix of the ride, 10 ms apart; a damaged block may take its
    // frames out, and only before the last block decoded if it is the one.
    let mut expected = 0u64;
    let mut gaps = 0u64;
    for (k, &index) in frames.iter().enumerate() {
        if index != expected {
            gaps += 1;
            assert!(
                index > expected,
                "{name}: frame {k} is {index}, expected {expected}"
            );
        }
        expected = index + 1;
    }
    assert!(
        gaps <= damaged,
        "{name}: {gaps} gaps in the frames, {damaged} damaged blocks"
    );
    assert!(logs.iter().all(|l| l.dropouts.is_empty()));
    let on_card = frames.len() as u64;
    // At most a flush period and the queue, plus the frames of a block the
    // cut damaged (a block holds fewer than a flush period's).
    let bound = FLUSH_FRAMES + QUEUE_SLACK_FRAMES + damaged * FLUSH_FRAMES;
    assert!(
        sampled - on_card <= bound,
        "{name}: {on_card} of {sampled} frames kept"
    );
    // Every check passed: the run's 40 MiB card image is not kept (a
    // campaign of cuts would fill a disk); a failed run keeps its directory.
    let _ = std::fs::remove_dir_all(&dir);
    Cut {
        sampled,
        frames,
        damaged,
        torn,
    }
}

#[test]
fn power_cut_inside_40_random_block_writes() {
    let bundle = qemu::bundle(FRAMES).expect("fixtures");
    let mut rng = Rng::new(0x7EA2);
    let mut cuts: Vec<(u32, u32)> = Vec::new();
    while cuts.len() < TORN_CUTS {
        let w = rng.range(1.0, f64::from(MAX_CUT_WRITE) + 1.0) as u32;
        let permille = rng.range(1.0, 1000.0) as u32;
        if !cuts.iter().any(|c| c.0 == w) {
            cuts.push((w, permille));
        }
    }
    let base = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let results = on_two_workers(&cuts, |&(w, p)| one_torn_cut(&bundle, base, w, p));
    let torn = results.iter().filter(|r| r.2 > 0).count();
    assert!(torn >= TORN_CUTS / 2, "only {torn} cuts left a block torn");
    let damaged: u64 = results.iter().map(|r| r.3).sum();
    let worst = results.iter().map(|r| r.0 - r.1).max().unwrap_or(0);
    println!(
        "FIGURES torn power cut: {} cuts inside block writes, {torn} of them into a block being \
         programmed, {damaged} left a damaged block (reported by the decoder); frames lost per cut worst {worst}",
        results.len()
    );
}
