//! `wobblog nmea`: replay a raw NMEA capture through the firmware's GPS path.
//!
//! The capture's bytes (without its `#` comment lines) go through exactly the
//! core's [`GpsReceiver`], in chunks as a UART DMA would deliver them, on a
//! synthetic clock: byte `i` arrives at `i` character times of `--baud`. Each
//! fix it emits is printed as one JSON object per line; counted faults are
//! summarised on stderr.

use std::io::{self, Read, Write};
use std::path::PathBuf;

use serde::Serialize;
use wobble_core::format::GpsFix;
use wobble_core::gps::{self, GpsConfig, GpsEvent, GpsReceiver, GpsStats};

use crate::output::Output;
use crate::time::iso8601;
use crate::CliError;

/// Bytes handed to the receiver at once, like a UART DMA half-buffer.
const CHUNK: usize = 64;
/// Bytes read from the capture at a time: a capture of any length (or a
/// device that never ends) is replayed in this much memory.
const READ_LEN: usize = 1 << 16;

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
    let mut out = Output::stdout(&[&args.input])?;
    let capture = std::fs::File::open(&args.input).map_err(|e| CliError::file(&args.input, e))?;
    let config = GpsConfig {
        baud: args.baud,
        ..GpsConfig::default()
    };
    let replayed = replay(capture, config, &mut |fix| write_fix(&mut out, fix));
    let stats = match replayed {
        Ok(stats) => stats,
        Err(ReplayError::Read(e)) => return Err(CliError::file(&args.input, e)),
        Err(ReplayError::Write(e)) => return Err(out.error(e)),
    };
    out.commit()?;
    for (code, &count) in (1u8..).zip(&stats.faults) {
        if count > 0 {
            let what = gps::fault_name(code).unwrap_or("other faults");
            eprintln!(
                "wobblog: {}: warning: {what}: {count}",
                crate::text::shown(&args.input)
            );
        }
    }
    Ok(())
}

fn write_fix(out: &mut impl Write, fix: &GpsFix) -> io::Result<()> {
    serde_json::to_writer(&mut *out, &FixJson::from(fix))?;
    out.write_all(b"\n")
}

/// Why a replay stopped early.
#[derive(Debug)]
pub enum ReplayError {
    /// The capture could not be read.
    Read(io::Error),
    /// A fix could not be passed on (`on_fix` failed).
    Write(io::Error),
}

/// Feeds `capture` (its `#` lines skipped) through the GPS path on a synthetic
/// clock, reading it as it goes, and hands every fix to `on_fix`, stopping
/// at its first error; returns the path's counters.
///
/// # Errors
/// The capture cannot be read, or `on_fix` failed.
pub fn replay(
    mut capture: impl Read,
    config: GpsConfig,
    on_fix: &mut impl FnMut(&GpsFix) -> io::Result<()>,
) -> Result<GpsStats, ReplayError> {
    let char_ns = 10_000_000_000 / u64::from(config.baud.max(1));
    let mut rx = GpsReceiver::new(config);
    let mut result = Ok(());
    let mut index = 0u64;
    let mut buf = vec![0u8; READ_LEN];
    // Whether the next byte starts a line, and whether the line being read
    // is a comment.
    let (mut line_start, mut comment) = (true, false);
    // A chunk being gathered: each line goes out in chunks of CHUNK bytes
    // from its start, however the reads split it.
    let mut pending: Vec<u8> = Vec::with_capacity(CHUNK);
    let mut feed = |chunk: &[u8], rx: &mut GpsReceiver, result: &mut io::Result<()>| {
        index += chunk.len() as u64;
        // The chunk's last byte arrived at the end of its character time.
        rx.feed(chunk, index * char_ns / 1000, &mut |e| {
            forward(e, on_fix, result);
        });
    };
    loop {
        let n = match capture.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(ReplayError::Read(e)),
        };
        let mut rest = &buf[..n];
        while let Some(&first) = rest.first() {
            if line_start {
                comment = first == b'#';
            }
            let end = rest
                .iter()
                .position(|&b| b == b'\n')
                .map_or(rest.len(), |i| i + 1);
            let (line, tail) = rest.split_at(end);
            line_start = line.ends_with(b"\n");
            rest = tail;
            if comment {
                continue;
            }
            let mut piece = line;
            while !piece.is_empty() {
                let take = (CHUNK - pending.len()).min(piece.len());
                pending.extend_from_slice(&piece[..take]);
                piece = &piece[take..];
                if pending.len() == CHUNK || (piece.is_empty() && line_start) {
                    feed(&pending, &mut rx, &mut result);
                    pending.clear();
                }
            }
            if let Err(e) = result {
                return Err(ReplayError::Write(e));
            }
        }
    }
    if !pending.is_empty() {
        feed(&pending, &mut rx, &mut result);
    }
    rx.finish(index * char_ns / 1000, &mut |e| {
        forward(e, on_fix, &mut result)
    });
    result.map_err(ReplayError::Write).map(|()| rx.stats())
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A reader handing out `step` bytes at a time.
    struct Trickle<'a>(&'a [u8], usize);

    impl Read for Trickle<'_> {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            let n = self.1.min(buf.len()).min(self.0.len());
            buf[..n].copy_from_slice(&self.0[..n]);
            self.0 = &self.0[n..];
            Ok(n)
        }
    }

    fn fixes(capture: impl Read) -> (Vec<GpsFix>, GpsStats) {
        let mut out = Vec::new();
        let stats = replay(capture, GpsConfig::default(), &mut |f| {
            out.push(*f);
            Ok(())
        })
        .unwrap();
        (out, stats)
    }

    #[test]
    fn a_capture_read_in_any_pieces_gives_the_same_fixes_and_skips_comments() {
        let mut text = String::from("# a comment line $GPRMC,not,a,sentence\r\n");
        for s in 0..30 {
            let body = format!(
                "GPRMC,1328{s:02}.00,A,4134.49821229,N,09345.03351845,W,3.252,92.308,180320,11.5985,E,D"
            );
            let sum = body.bytes().fold(0u8, |a, b| a ^ b);
            text.push_str(&format!("${body}*{sum:02X}\r\n"));
            if s % 7 == 0 {
                text.push_str("#$GPRMC,comment\r\n");
            }
        }
        let (whole, stats) = fixes(text.as_bytes());
        assert!(whole.len() >= 29, "{}", whole.len());
        assert_eq!(stats.faults.iter().sum::<u32>(), 0, "{stats:?}");
        for step in [1, 7, 64, 1000] {
            assert_eq!(fixes(Trickle(text.as_bytes(), step)).0, whole, "{step}");
        }
    }
}
