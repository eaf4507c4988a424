//! Writes the 64 MiB logs the memory and time figures in
//! `docs/robustness.md` are measured on: a clean 7.6 h log, one block
//! repeated through the file, a block of far-future times in front of the
//! clean log, a log whose clock jumps a year forward every block, a
//! busy 7.3 h ride whose every column moves (the slowest to export), the
//! clean log with its blocks in reverse order (decoded in sequence order),
//! back-to-back sync markers, and markers whose length fields pass (each
//! one a candidate block whose CRC must be checked), with a short payload
//! and with a full one; a kick campaign (a ring-down every 12 s); and the
//! clean log with a card kick record every 20 frames (131 k records).
//!
//! ```text
//! cargo run -p wobblog --release --example absurd_logs -- OUT_DIR
//! ```

use std::f64::consts::TAU;
use std::io::Write;

use wobble_core::format::{
    BlockEncoder, FixMode, Frame, GpsFix, KickRingDown, Record, UtcSync, UtcTime,
    STEER_COUNTS_PER_DEG,
};

/// Size of each log.
const LEN: usize = 64 << 20;
const YEAR_US: u64 = 365 * 86_400_000_000;

/// A steady 1-degree 6.4 Hz steering wobble at frame `i`, degrees.
fn wobble(i: u64) -> f64 {
    (TAU * 6.4 * i as f64 / 100.0).sin()
}

/// A kick campaign at frame `i`, degrees: every 12 s from 5 s a 0.1 s
/// push of 4 degrees, then a 6.5 Hz ring of 1.5 degrees decaying at
/// 0.8/s, over 0.02 degrees of noise (a fixed-seed generator).
fn kicked(i: u64) -> f64 {
    let t = i as f64 / 100.0;
    let since = (t - 5.0).rem_euclid(12.0);
    let kick = if t < 5.0 {
        0.0
    } else if since < 0.1 {
        4.0
    } else {
        let s = since - 0.1;
        1.5 * (-0.8 * s).exp() * (TAU * 6.5 * s).sin()
    };
    // SplitMix64 of the frame number: the same noise on every run.
    let mut z = i.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    let unit = ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64;
    kick + 0.02 * (2.0 * unit - 1.0) * 3f64.sqrt()
}

/// Frames at 100 Hz from `t0_us`, steering `steer_deg(frame)`, until the
/// file holds `len` bytes; `jump_us` is added at every new block; a card
/// kick record after every `kick_every`-th frame if given (with the speed
/// it gives, or none).
fn log(
    t0_us: u64,
    jump_us: u64,
    len: usize,
    steer_deg: fn(u64) -> f64,
    kick_every: Option<(u64, Option<u16>)>,
) -> Vec<u8> {
    let mut enc = BlockEncoder::new();
    let mut file = Vec::with_capacity(len);
    let mut t_us = t0_us;
    let mut i = 0u64;
    while file.len() < len {
        let frame = Frame {
            t_us,
            steer_cdeg: (steer_deg(i) * f64::from(STEER_COUNTS_PER_DEG)) as i16,
            speed_mm_s: 4000,
            ..Frame::default()
        };
        if let Ok(Some(block)) = enc.push(&Record::Frame(frame)) {
            file.extend_from_slice(block);
            t_us += jump_us;
        }
        if let Some((_, speed_mm_s)) = kick_every.filter(|&(k, _)| i % k == k - 1) {
            let kick = KickRingDown {
                t_us,
                speed_mm_s,
                freq_chz: 650,
                sigma_milli_per_s: -800,
                sigma_se_milli_per_s: 50,
                amp_cdeg: 150,
                segments: 6,
            };
            if let Ok(Some(block)) = enc.push(&Record::Kick(kick)) {
                file.extend_from_slice(block);
            }
        }
        t_us += 10_000;
        i += 1;
    }
    file.truncate(len);
    file
}

/// A ride whose every exported column moves: IMU axes and steering at
/// full 16-bit scale, speed, GPS fixes at 20 Hz and a UTC sync pair each
/// second, so no cell is a zero or a repeat (the number formatter's fast cases).
fn busy(len: usize) -> Vec<u8> {
    let mut enc = BlockEncoder::new();
    let mut file = Vec::with_capacity(len);
    let mut push = |file: &mut Vec<u8>, record: Record| {
        if let Ok(Some(block)) = enc.push(&record) {
            file.extend_from_slice(block);
        }
    };
    let mut i = 0u64;
    while file.len() < len {
        let t_us = 1_000_000 + i * 10_000;
        let wave = |k: u64| ((i * k) % 65_521) as i16;
        let frame = Frame {
            t_us,
            accel: [wave(7919), wave(104_729), wave(1_299_709)],
            gyro: [wave(15_485_863), wave(32_452_843), wave(49_979_687)],
            steer_cdeg: wave(86_028_121),
            speed_mm_s: 2_000 + (i % 6_000) as u16,
            ..Frame::default()
        };
        push(&mut file, Record::Frame(frame));
        if i.is_multiple_of(5) {
            let gps = GpsFix {
                t_us,
                utc: Some(UtcTime {
                    days_since_2000: 9_800,
                    ms_of_day: (i * 10 % 86_400_000) as u32,
                }),
                lat_e7: Some(520_000_000 + (i * 37 % 1_000_000) as i32),
                lon_e7: Some(43_000_000 + (i * 53 % 1_000_000) as i32),
                speed_cm_s: Some(200 + (i % 600) as u16),
                fix: FixMode::Fix3d,
                ..GpsFix::default()
            };
            push(&mut file, Record::Gps(gps));
        }
        if i.is_multiple_of(100) {
            let unix_ms = 1_796_000_000_000 + i * 10;
            push(&mut file, Record::UtcSync(UtcSync { t_us, unix_ms }));
        }
        i += 1;
    }
    file.truncate(len);
    file
}

fn main() -> std::io::Result<()> {
    let dir = std::path::PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| ".".into()));
    let write = |name: &str, bytes: &[u8]| {
        std::fs::File::create(dir.join(name)).and_then(|mut f| f.write_all(bytes))
    };
    let clean = log(1_000_000, 0, LEN, wobble, None);
    write("clean.wbl", &clean)?;
    write("repeated.wbl", &clean[..512].repeat(LEN / 512))?;
    let mut front = log(1 << 62, 0, 512, wobble, None);
    front.extend_from_slice(&clean[..LEN - 512]);
    write("front.wbl", &front)?;
    write("jumps.wbl", &log(1_000_000, YEAR_US, LEN, wobble, None))?;
    let reversed: Vec<u8> = clean.chunks(512).rev().flatten().copied().collect();
    write("reversed.wbl", &reversed)?;
    write("markers.wbl", &b"WBLK".repeat(LEN / 4))?;
    write("candidates.wbl", &b"WBLK\x01\x00\x10\x00".repeat(LEN / 8))?;
    // Length 484: a full payload, so no zero padding could tell these apart.
    write(
        "full_candidates.wbl",
        &b"WBLK\x01\x00\xe4\x01".repeat(LEN / 8),
    )?;
    write("kicked.wbl", &log(1_000_000, 0, LEN, kicked, None))?;
    write(
        "kick_records.wbl",
        &log(1_000_000, 0, LEN, wobble, Some((20, Some(4000)))),
    )?;
    // The same without a speed: margin takes each record's speed from the
    // frames after it.
    write(
        "speedless_records.wbl",
        &log(1_000_000, 0, LEN, wobble, Some((20, None))),
    )?;
    write("busy.wbl", &busy(LEN))
}
