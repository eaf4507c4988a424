//! A stable-toolchain fuzz harness over what every `wobblog` command runs:
//! the decoder and log reader, rows, info, decode in each format, the
//! analyses and both figures, GPX, events, config, and the CSV and NMEA
//! paths. Inputs are card logs whose blocks carry a valid CRC but absurd
//! content (frame times jumping by years or standing still, sample rates and
//! channel scales of any value, header records of every length, GPS fields
//! of any value, repeated blocks), then some of them flipped or cut; and
//! arbitrary CSV and NMEA text. Nothing may panic, and memory-bound
//! invariants must hold.
//!
//! The test command runs one round of 8 new cases per harness, drawn from
//! the fixed proptest seed (`PROPTEST_RNG_SEED`, `.cargo/config.toml`), so
//! every run of one tree tests the same cases; with `WOBBLOG_FUZZ_SECONDS`
//! it runs rounds for that long, each from the next seed; for a long run
//! (fresh seeds: `hil-tests/proptest-fresh.sh`):
//!
//! ```text
//! WOBBLOG_FUZZ_SECONDS=600 cargo test -p wobblog --release --test fuzz_commands -- --nocapture
//! ```

use std::io::Write;
use std::path::Path;
use std::time::{Duration, Instant};

use proptest::collection::vec;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestRunner};
use wobble_core::format::block::BlockHeader;
use wobble_core::format::{
    Block, BlockEncoder, ChannelDef, ConfigLine, FixMode, Frame, GpsFix, LogInfo, Record, UtcSync,
    UtcTime, BLOCK_LEN,
};
use wobblog::analysis::{Ride, Run};
use wobblog::cmd::{decode, detect, encode, gpx, nmea};
use wobblog::export::Format;
use wobblog::plot::modes::ModePlot;
use wobblog::plot::timeplot::TimePlot;
use wobblog::plot::Figure;
use wobblog::time::TimeWindow;

/// One record of a generated log, owning its text.
#[derive(Clone, Debug)]
enum Item {
    Frame { dt_us: i64, steer: i16, speed: u16 },
    Jump { to_us: u64 },
    Gps(GpsFix),
    Sync(u64),
    Info { rate: u16, firmware: String },
    Channel { index: u8, scale: f32, name: String },
    Config(String),
}

/// What to do to the encoded blocks.
#[derive(Clone, Debug)]
struct Damage {
    /// Copies of block `.0` appended `.1` times (repeated blocks).
    repeats: Vec<(prop::sample::Index, u16)>,
    /// Bytes flipped: (block, byte, mask).
    flips: Vec<(prop::sample::Index, usize, u8)>,
    /// Bytes cut from the end.
    cut: usize,
}

fn item() -> impl Strategy<Value = Item> {
    let gps = (
        any::<Option<(u16, u32)>>(),
        any::<Option<(i32, i32)>>(),
        any::<Option<u16>>(),
        any::<Option<i32>>(),
        any::<Option<u8>>(),
        0u8..3,
    )
        .prop_map(|(utc, pos, speed, alt, sats, mode)| {
            Item::Gps(GpsFix {
                t_us: 0,
                utc: utc.map(|(days_since_2000, ms_of_day)| UtcTime {
                    days_since_2000,
                    ms_of_day,
                }),
                lat_e7: pos.map(|p| p.0),
                lon_e7: pos.map(|p| p.1),
                speed_cm_s: speed,
                alt_cm: alt,
                sats,
                fix: [FixMode::None, FixMode::Fix2d, FixMode::Fix3d][usize::from(mode)],
                ..GpsFix::default()
            })
        });
    prop_oneof![
        40 => (prop_oneof![9_000i64..11_000, -1_000_000i64..2_000_000], any::<i16>(), any::<u16>())
            .prop_map(|(dt_us, steer, speed)| Item::Frame { dt_us, steer, speed }),
        1 => prop_oneof![Just(0u64), Just(1 << 62), Just(u64::MAX / 2), 0u64..(400 * 86_400_000_000)]
            .prop_map(|to_us| Item::Jump { to_us }),
        4 => gps,
        1 => any::<u64>().prop_map(Item::Sync),
        1 => (any::<u16>(), "(?s).{0,200}").prop_map(|(rate, firmware)| Item::Info { rate, firmware }),
        1 => (any::<u8>(), prop_oneof![Just(0.0f32), Just(f32::NAN), Just(f32::INFINITY), Just(1e38), any::<f32>()], "(?s).{0,60}")
            .prop_map(|(index, scale, name)| Item::Channel { index, scale, name }),
        1 => "(?s).{0,240}".prop_map(Item::Config),
    ]
}

fn damage() -> impl Strategy<Value = Damage> {
    (
        vec((any::<prop::sample::Index>(), 0u16..300), 0..3),
        vec(
            (any::<prop::sample::Index>(), 0..BLOCK_LEN, 1u8..=255),
            0..4,
        ),
        prop_oneof![3 => Just(0usize), 1 => 0usize..1200],
    )
        .prop_map(|(repeats, flips, cut)| Damage {
            repeats,
            flips,
            cut,
        })
}

/// The log the items describe, damaged. Header records that do not fit a
/// block are skipped (the encoder refuses them, as it should).
fn build(items: &[Item], damage: &Damage) -> Vec<u8> {
    let mut enc = BlockEncoder::new();
    let mut blocks: Vec<[u8; BLOCK_LEN]> = Vec::new();
    let mut t_us = 1_000_000u64;
    for it in items {
        let rec = match it {
            Item::Frame {
                dt_us,
                steer,
                speed,
            } => {
                t_us = t_us.saturating_add_signed(*dt_us);
                Record::Frame(Frame {
                    t_us,
                    steer_cdeg: *steer,
                    speed_mm_s: *speed,
                    ..Frame::default()
                })
            }
            Item::Jump { to_us } => {
                t_us = *to_us;
                continue;
            }
            Item::Gps(fix) => Record::Gps(GpsFix { t_us, ..*fix }),
            Item::Sync(unix_ms) => Record::UtcSync(UtcSync {
                t_us,
                unix_ms: *unix_ms,
            }),
            Item::Info { rate, firmware } => Record::LogInfo(LogInfo {
                t_us,
                firmware,
                device_id: [0xa5; 12],
                sample_rate_hz: *rate,
                run: 7,
            }),
            Item::Channel { index, scale, name } => Record::Channel(ChannelDef {
                t_us,
                index: *index,
                name,
                unit: "u",
                counts_per_unit: *scale,
            }),
            Item::Config(text) => Record::Config(ConfigLine { t_us, text }),
        };
        if let Ok(Some(b)) = enc.push(&rec) {
            blocks.push(*b);
        }
    }
    if let Some(b) = enc.finish() {
        blocks.push(*b);
    }
    if blocks.is_empty() {
        return Vec::new();
    }
    for (which, times) in &damage.repeats {
        let b = blocks[which.index(blocks.len())];
        blocks.extend(std::iter::repeat_n(b, usize::from(*times)));
    }
    for (which, byte, mask) in &damage.flips {
        let n = blocks.len();
        blocks[which.index(n)][*byte] ^= mask;
    }
    let mut file: Vec<u8> = blocks.concat();
    file.truncate(file.len().saturating_sub(damage.cut));
    file
}

/// Runs what every log-reading command runs on the log at `path`.
fn every_log_command(path: &Path, dir: &Path) {
    let summary = wobblog::cmd::info::summarise(path);
    let Ok(summary) = summary else {
        return;
    };
    assert!(summary.duration_s.is_finite() && summary.duration_s >= 0.0);
    assert!(serde_json::to_string(&summary).is_ok());
    for format in [Format::Csv, Format::Jsonl, Format::Parquet] {
        let export = decode::Export::all(format);
        let _ = decode::decode_to(path, &export, std::io::sink(), Path::new("sink"));
    }
    let _ = detect::replay_log(path, &wobble_core::config::Config::default());
    let mut track = gpx::Gpx::new(std::io::sink(), "fuzz");
    let walked = gpx::track(path, TimeWindow::default(), |step| {
        if let gpx::Step::Point(fix, _) = step {
            let (lat, lon) = (fix.lat_e7.unwrap_or(0), fix.lon_e7.unwrap_or(0));
            assert!(lat.unsigned_abs() <= 900_000_000 && lon.unsigned_abs() <= 1_800_000_000);
            assert!(fix.utc.is_none_or(UtcTime::is_valid));
        }
        track.step(step)
    });
    if let Ok(walked) = walked {
        walked.and_then(|()| track.finish()).unwrap();
    }
    let _ = wobblog::cmd::config::read_header(path);
    if let (Ok(run), Ok(ride)) = (Run::load(path), Ride::load(path)) {
        let episodes = ride.episodes.clone();
        for e in &episodes {
            assert!(e.sigma_per_s.is_finite() && e.freq_hz.is_finite(), "{e:?}");
        }
        let row = wobblog::cmd::summary::RunRow::of(&ride);
        assert!(row.distance_m.is_finite(), "{row:?}");
        draw(
            &ModePlot::new(vec![("fuzz".into(), episodes)]),
            dir,
            "modes.svg",
        );
        if let Some(plot) = TimePlot::new(&run, None, None) {
            draw(&plot, dir, "run.svg");
        }
        let report = wobblog::report::Campaign::load(&[path.to_path_buf()], None).unwrap();
        let html = wobblog::report::page::render(&report).unwrap();
        assert!(html.ends_with("</html>\n"));
    }
}

/// Draws `figure` through the command's own output path.
fn draw(figure: &impl Figure, dir: &Path, name: &str) {
    let out = wobblog::output::Output::create(&dir.join(name), &[]).unwrap();
    wobblog::plot::render(figure, out, &wobblog::plot::FigureArgs::default()).unwrap();
}

/// Time for new cases for each harness, from `WOBBLOG_FUZZ_SECONDS`; none
/// (one round) without it.
fn budget() -> Duration {
    let s = std::env::var("WOBBLOG_FUZZ_SECONDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0.0);
    Duration::from_secs_f64(s)
}

/// The seed of round `round`: the configured seed's `round`-th successor
/// when it is fixed, else a fresh one.
fn seed_of(round: u64) -> RngSeed {
    match Config::default().rng_seed {
        RngSeed::Fixed(seed) => RngSeed::Fixed(seed.wrapping_add(round)),
        RngSeed::Random => RngSeed::Random,
    }
}

/// Runs `test` on values of `strategy` until the budget is spent; a failure
/// is shrunk and reported with its minimal input (then saved as a case in
/// this file's regression tests).
fn fuzz<S: Strategy>(name: &str, strategy: S, test: impl Fn(S::Value)) {
    let start = Instant::now();
    let mut cases = 0u32;
    let mut round = 0;
    while cases == 0 || start.elapsed() < budget() {
        // A runner stops after its number of cases: a new one, with the
        // next seed, for every round.
        let mut runner = TestRunner::new(Config {
            cases: 8,
            failure_persistence: None,
            rng_seed: seed_of(round),
            ..Config::default()
        });
        round += 1;
        let result = runner.run(&strategy, |v| {
            test(v);
            Ok(())
        });
        if let Err(e) = result {
            panic!("{name}: {e}");
        }
        cases += 8;
    }
    eprintln!(
        "{name}: {cases} cases in {:.1} s",
        start.elapsed().as_secs_f64()
    );
}

#[test]
fn crc_valid_absurd_logs_through_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fuzz.wbl");
    fuzz(
        "logs",
        (vec(item(), 0..1500), damage()),
        |(items, damage)| {
            let file = build(&items, &damage);
            std::fs::File::create(&path)
                .and_then(|mut f| f.write_all(&file))
                .unwrap();
            every_log_command(&path, dir.path());
        },
    );
}

#[test]
fn arbitrary_csv_through_encode_and_detect() {
    let header = prop_oneof![
        Just("t_s,steer_deg,speed_mps".to_string()),
        Just("t_s,ax_g,ay_g,az_g,gx_dps,gy_dps,gz_dps,steer_deg,speed_mps,gps_lat_deg,gps_lon_deg,gps_speed_mps,gps_fix".to_string()),
        "[a-z_,]{0,40}",
    ];
    let cell = prop_oneof![
        Just(String::new()),
        Just("NaN".to_string()),
        Just("inf".to_string()),
        Just("3d".to_string()),
        any::<f64>().prop_map(|v| v.to_string()),
        (-1000.0..1000.0f64).prop_map(|v| format!("{v:.3}")),
        "(?s).{0,6}",
    ];
    let rows = vec(vec(cell, 0..14), 0..200);
    fuzz(
        "csv",
        (header, rows, any::<bool>()),
        |(header, rows, at_100_hz)| {
            let mut text = header + "\n";
            for (i, row) in rows.iter().enumerate() {
                if at_100_hz && !row.is_empty() {
                    text.push_str(&format!("{}", i as f64 / 100.0));
                    for c in &row[1..] {
                        text.push(',');
                        text.push_str(c);
                    }
                } else {
                    text.push_str(&row.join(","));
                }
                text.push('\n');
            }
            for resample in [false, true] {
                let _ = encode::encode(
                    text.as_bytes(),
                    Path::new("in.csv"),
                    std::io::sink(),
                    Path::new("out"),
                    resample,
                );
            }
            let _ = detect::replay(
                Path::new("in.csv"),
                text.as_bytes(),
                &wobble_core::config::Config::default(),
            );
        },
    );
}

#[test]
fn arbitrary_nmea_through_the_gps_path() {
    let field = prop_oneof![
        Just(String::new()),
        "[0-9]{1,12}(\\.[0-9]{0,8})?",
        "-?[0-9]{1,3}",
        "[NSEWAVMTK]",
        "(?s).{0,5}",
    ];
    let sentence = (
        prop_oneof![
            Just("GPRMC"),
            Just("GNGGA"),
            Just("GPGLL"),
            Just("GPVTG"),
            Just("GPGSA"),
            Just("GPZDA"),
            Just("PMTK")
        ],
        vec(field, 0..20),
        any::<bool>(),
    )
        .prop_map(|(address, fields, checksum)| {
            let body = format!("{address},{}", fields.join(","));
            let sum = body.bytes().fold(0u8, |a, b| a ^ b);
            if checksum {
                format!("${body}*{sum:02X}\r\n")
            } else {
                format!("${body}\r\n")
            }
        });
    fuzz("nmea", vec(sentence, 0..60), |lines| {
        let capture = lines.concat();
        let mut fixes = Vec::new();
        let config = wobble_core::gps::GpsConfig::default();
        nmea::replay(capture.as_bytes(), config, &mut |f| {
            fixes.push(*f);
            Ok(())
        })
        .unwrap();
        for f in fixes {
            assert!(
                f.lat_e7.is_none_or(|v| v.unsigned_abs() <= 900_000_000),
                "{f:?}"
            );
            assert!(
                f.lon_e7.is_none_or(|v| v.unsigned_abs() <= 1_800_000_000),
                "{f:?}"
            );
            assert!(f.utc.is_none_or(UtcTime::is_valid), "{f:?}");
            assert!(f.sats.is_none_or(|n| n <= 99), "{f:?}");
        }
    });
}

/// A log's blocks in any order, with copies, earlier flushes of blocks and
/// blocks that share a number but not their content: every frame of the
/// log comes out once, in time order, with nothing counted lost; a block
/// changed behind its number adds its own frames and hides none.
#[test]
fn reordered_copied_and_rewritten_blocks() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("order.wbl");
    let shuffle = vec(any::<prop::sample::Index>(), 0..40);
    let extras = vec((any::<prop::sample::Index>(), 0u8..3, any::<u8>()), 0..6);
    fuzz(
        "order",
        (50usize..1500, vec(any::<bool>(), 1500), shuffle, extras),
        |(frames, flush_at, swaps, extras)| {
            // Frames 10 ms apart, each with its own steering value;
            // flushes (snapshots of the open block) wherever asked.
            let mut enc = BlockEncoder::new();
            let mut blocks: Vec<Block> = Vec::new();
            let mut flushes: Vec<Block> = Vec::new();
            for (i, flush) in flush_at.iter().enumerate().take(frames) {
                let rec = Record::Frame(Frame {
                    t_us: 1_000_000 + i as u64 * 10_000,
                    steer_cdeg: i as i16,
                    ..Frame::default()
                });
                blocks.extend(enc.push(&rec).unwrap().copied());
                if *flush {
                    flushes.extend(enc.snapshot().copied());
                }
            }
            blocks.extend(enc.finish().copied());
            let unique = blocks.len() as u64;
            let mut file: Vec<Block> = blocks.clone();
            file.extend(flushes.iter().step_by(7).copied());
            let mut changed = 0;
            for (which, kind, byte) in &extras {
                let b = blocks[which.index(blocks.len())];
                match kind {
                    0 => file.push(b),
                    1 => {
                        // Another block with the same number: a payload
                        // byte changed, resealed.
                        let mut other = b;
                        let h = BlockHeader::parse(&other).unwrap();
                        let at = 24 + usize::from(*byte) % usize::from(h.payload_len.max(1));
                        other[at] ^= 0x5a;
                        h.seal(&mut other);
                        file.push(other);
                        changed += 1;
                    }
                    _ => file.insert(0, b),
                }
            }
            for (k, at) in swaps.iter().enumerate() {
                let n = file.len();
                file.swap(k % n, at.index(n));
            }
            std::fs::write(&path, file.concat()).unwrap();
            let mut steer = Vec::new();
            let stats = wobblog::reader::read_log(&path, |e| {
                if let wobble_core::format::Event::Record(Record::Frame(f)) = e {
                    steer.push(f.steer_cdeg);
                }
            })
            .unwrap();
            let all: Vec<i16> = (0..frames as i16).collect();
            if changed == 0 {
                assert_eq!(steer, all);
                assert_eq!(stats.blocks, unique);
                assert_eq!(stats.frames, frames as u64);
                assert_eq!(stats.blocks_lost + stats.frames_lost, 0);
            } else {
                let mut seen = steer.clone();
                seen.sort_unstable();
                seen.dedup();
                for v in &all {
                    assert!(seen.binary_search(v).is_ok(), "frame {v} lost");
                }
            }
            every_log_command(&path, dir.path());
        },
    );
}

/// A block whose header is resealed with `edit` still decodes without panic
/// through every command, whatever its header says.
#[test]
fn resealed_block_headers() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("hdr.wbl");
    fuzz(
        "headers",
        (any::<u32>(), any::<u32>(), any::<u64>(), 0usize..8),
        |(seq, first_frame, t0_us, which)| {
            let items: Vec<Item> = (0..400)
                .map(|_| Item::Frame {
                    dt_us: 10_000,
                    steer: 100,
                    speed: 4000,
                })
                .collect();
            let mut file = build(
                &items,
                &Damage {
                    repeats: Vec::new(),
                    flips: Vec::new(),
                    cut: 0,
                },
            );
            let n = file.len() / BLOCK_LEN;
            let i = which % n;
            let block: &mut Block = (&mut file[i * BLOCK_LEN..(i + 1) * BLOCK_LEN])
                .try_into()
                .unwrap();
            let mut h = BlockHeader::parse(block).unwrap();
            h.seq = seq;
            h.first_frame = first_frame;
            h.t0_us = t0_us;
            h.seal(block);
            std::fs::write(&path, &file).unwrap();
            every_log_command(&path, dir.path());
        },
    );
}
