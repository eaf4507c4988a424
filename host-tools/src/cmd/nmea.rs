//! `wobblog nmea`: replay a raw NMEA capture through the firmware's GPS path.
//!
//! The capture's bytes (without its `#` comment lines) go through exactly the
//! core's [`GpsReceiver`], in chunks as a UART DMA would deliver them, on a
//! synthetic clock: byte `i` arrives at `i` character times of `--baud`. Each
//! fix it emits is printed as one JSON object per line; counted faults are
//! summarised on stderr.

use std::io::{self, Write};
use std::path::PathBuf;

use serde::Serialize;
use wobble_core::format::GpsFix;
use wobble_core::gps::{self, GpsConfig, GpsEvent, GpsReceiver, GpsStats};

use crate::output::Output;
use crate::time::iso8601;
use crate::CliError;

/// Bytes handed to the receiver at once, like a UART DMA half-buffer.
const CHUNK: usize = 64;

/// Arguments of `wobblog nmea`.
#[derive(clap::Args)]
pub struct Args {
    /// Raw NMEA capture: the bytes a receiver sent; lines starting with `#`
    /// are skipped.
    pub input: PathBuf,
    /// Baud rate of the synthetic clock (10 bits per byte).
    #[arg(long, default_value_t = 115_200, value_parser = clap::value_parser!(u32).range(300..))]
    pub baud: u32,
}

/// One fix as a JSON line; absent fields are left out.
#[derive(Serialize)]
struct FixJson {
    #[serde(skip_serializing_if = "Option::is_none")]
    time: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    lat: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    lon: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    speed_mps: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    course_deg: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    alt_m: Option<f64>,
    fix: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    sats: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    hdop: Option<f64>,
}

impl From<&GpsFix> for FixJson {
    fn from(f: &GpsFix) -> Self {
        // Integer / power of ten is the double nearest the decimal, so JSON
        // shows exactly the stored digits.
        Self {
            time: f.utc.map(iso8601),
            lat: f.lat_e7.map(|v| f64::from(v) / 1e7),
            lon: f.lon_e7.map(|v| f64::from(v) / 1e7),
            speed_mps: f.speed_cm_s.map(|v| f64::from(v) / 100.0),
            course_deg: f.course_cdeg.map(|v| f64::from(v) / 100.0),
            alt_m: f.alt_cm.map(|v| f64::from(v) / 100.0),
            fix: f.fix.as_str(),
            sats: f.sats,
            hdop: f.hdop_d.map(|v| f64::from(v) / 10.0),
        }
    }
}

/// Runs `wobblog nmea`.
pub fn run(args: &Args) -> Result<(), CliError> {
    let capture = std::fs::read(&args.input).map_err(|e| CliError::file(&args.input, e))?;
    let config = GpsConfig {
        baud: args.baud,
        ..GpsConfig::default()
    };
    let mut out = Output::stdout();
    let replayed = replay(&capture, config, &mut |fix| write_fix(&mut out, fix));
    let stats = replayed.map_err(|e| out.error(e))?;
    out.commit()?;
    for (code, &count) in (1u8..).zip(&stats.faults) {
        if count > 0 {
            let what = gps::fault_name(code).unwrap_or("other faults");
            eprintln!(
                "wobblog: {}: warning: {what}: {count}",
                args.input.display()
            );
        }
    }
    Ok(())
}

fn write_fix(out: &mut impl Write, fix: &GpsFix) -> io::Result<()> {
    serde_json::to_writer(&mut *out, &FixJson::from(fix))?;
    out.write_all(b"\n")
}

/// Feeds `capture` (its `#` lines skipped) through the GPS path on a synthetic
/// clock and hands every fix to `on_fix`, stopping at its first error;
/// returns the path's counters.
pub fn replay(
    capture: &[u8],
    config: GpsConfig,
    on_fix: &mut impl FnMut(&GpsFix) -> io::Result<()>,
) -> io::Result<GpsStats> {
    let char_ns = 10_000_000_000 / u64::from(config.baud.max(1));
    let mut rx = GpsReceiver::new(config);
    let mut result = Ok(());
    let mut index = 0u64;
    let lines = capture
        .split_inclusive(|&b| b == b'\n')
        .filter(|l| !l.starts_with(b"#"));
    for line in lines {
        for chunk in line.chunks(CHUNK) {
            index += chunk.len() as u64;
            // The chunk's last byte arrived at the end of its character time.
            rx.feed(chunk, index * char_ns / 1000, &mut |e| {
                forward(e, on_fix, &mut result);
            });
        }
        if result.is_err() {
            return result.map(|()| rx.stats());
        }
    }
    rx.finish(index * char_ns / 1000, &mut |e| {
        forward(e, on_fix, &mut result)
    });
    result.map(|()| rx.stats())
}

fn forward(
    event: GpsEvent,
    on_fix: &mut impl FnMut(&GpsFix) -> io::Result<()>,
    result: &mut io::Result<()>,
) {
    if let (GpsEvent::Fix(fix), Ok(())) = (event, &result) {
        *result = on_fix(&fix);
    }
}
