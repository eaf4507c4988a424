//! Writes the 64 MiB logs the memory and time figures in
//! `docs/robustness.md` are measured on: a clean 7.6 h log, one block
//! repeated through the file, a block of far-future times in front of the
//! clean log, and a log whose clock jumps a year forward every block.
//!
//! ```text
//! cargo run -p wobblog --release --example absurd_logs -- OUT_DIR
//! ```

use std::f64::consts::TAU;
use std::io::Write;

use wobble_core::format::{BlockEncoder, Frame, Record, STEER_COUNTS_PER_DEG};

/// Size of each log.
const LEN: usize = 64 << 20;
const YEAR_US: u64 = 365 * 86_400_000_000;

/// Frames at 100 Hz from `t0_us`, with a 6.4 Hz steering wobble, until the
/// file holds `len` bytes; `jump_us` is added at every new block.
fn log(t0_us: u64, jump_us: u64, len: usize) -> Vec<u8> {
    let mut enc = BlockEncoder::new();
    let mut file = Vec::with_capacity(len);
    let mut t_us = t0_us;
    let mut i = 0u64;
    while file.len() < len {
        let steer_deg = (TAU * 6.4 * i as f64 / 100.0).sin();
        let frame = Frame {
            t_us,
            steer_cdeg: (steer_deg * f64::from(STEER_COUNTS_PER_DEG)) as i16,
            speed_mm_s: 4000,
            ..Frame::default()
        };
        if let Ok(Some(block)) = enc.push(&Record::Frame(frame)) {
            file.extend_from_slice(block);
            t_us += jump_us;
        }
        t_us += 10_000;
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
    let clean = log(1_000_000, 0, LEN);
    write("clean.wbl", &clean)?;
    write("repeated.wbl", &clean[..512].repeat(LEN / 512))?;
    let mut front = log(1 << 62, 0, 512);
    front.extend_from_slice(&clean[..LEN - 512]);
    write("front.wbl", &front)?;
    write("jumps.wbl", &log(1_000_000, YEAR_US, LEN))
}
