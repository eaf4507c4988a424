//! `wobblog gpx`: the run's GPS track as GPX 1.1, for maps and GIS tools.

use std::io::Write;
use std::path::{Path, PathBuf};

use quick_xml::events::{BytesDecl, BytesText, Event};
use quick_xml::Writer;
use wobble_core::format::{Event as LogEvent, GpsFix, Record};

use crate::output::Output;
use crate::reader::read_log;
use crate::rows::GpsColumns;
use crate::time::{TimeWindow, WindowArgs};
use crate::CliError;

/// Arguments of `wobblog gpx`.
#[derive(clap::Args)]
pub struct Args {
    /// The card log (`RUNnnnnn.WBL`).
    pub log: PathBuf,
    /// Output file; standard output if absent.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Only fixes in this window (`--from`, `--to`; a UTC bound is compared
    /// with each fix's own UTC time).
    #[command(flatten)]
    pub window: WindowArgs,
}

/// A new track segment starts after this long without a fix, µs, or after
/// a fix was lost: a straight line across the gap would be made up.
const SEGMENT_GAP_US: u64 = 5_000_000;

/// Runs `wobblog gpx`.
pub fn run(args: &Args) -> Result<(), CliError> {
    let mut out = Output::create_or_stdout(args.output.as_deref(), &[&args.log])?;
    let segments = track(&args.log, args.window.window())?;
    if segments.is_empty() {
        eprintln!(
            "wobblog: {}: warning: no GPS fix with a position; the track is empty",
            args.log.display()
        );
    }
    let name = args
        .log
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    write_gpx(&mut out, &name, &segments).map_err(|e| out.error(e))?;
    out.commit()
}

/// The fixes with a position inside `window`, split into segments at gaps.
pub fn track(log: &Path, window: TimeWindow) -> Result<Vec<Vec<GpsFix>>, CliError> {
    let mut segments: Vec<Vec<GpsFix>> = Vec::new();
    let mut open = false;
    read_log(log, |event| {
        let LogEvent::Record(Record::Gps(fix)) = event else {
            // A block lost from the file may have held fixes.
            open &= !matches!(event, LogEvent::Gap(_));
            return;
        };
        let utc_ms = fix.utc.and_then(|u| i64::try_from(u.unix_ms()).ok());
        if GpsColumns::from_fix(&fix).is_none() || !window.contains(fix.t_us as f64 / 1e6, utc_ms) {
            open = false;
            return;
        }
        match segments.last_mut() {
            Some(seg)
                if open
                    && seg
                        .last()
                        .is_some_and(|p| fix.t_us.saturating_sub(p.t_us) <= SEGMENT_GAP_US) =>
            {
                seg.push(fix);
            }
            _ => segments.push(vec![fix]),
        }
        open = true;
    })?;
    Ok(segments)
}

/// Writes the track as GPX 1.1.
pub fn write_gpx(out: impl Write, name: &str, segments: &[Vec<GpsFix>]) -> std::io::Result<()> {
    let mut w = Writer::new_with_indent(out, b' ', 1);
    w.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))?;
    w.create_element("gpx")
        .with_attribute(("version", "1.1"))
        .with_attribute(("creator", concat!("wobblog ", env!("CARGO_PKG_VERSION"))))
        .with_attribute(("xmlns", "http://www.topografix.com/GPX/1/1"))
        .write_inner_content(|w| {
            w.create_element("trk").write_inner_content(|w| {
                w.create_element("name")
                    .write_text_content(BytesText::new(name))?;
                for seg in segments {
                    w.create_element("trkseg").write_inner_content(|w| {
                        seg.iter().try_for_each(|fix| write_point(w, fix))
                    })?;
                }
                Ok(())
            })?;
            Ok(())
        })?;
    w.into_inner().flush()
}

fn write_point<W: Write>(w: &mut Writer<W>, fix: &GpsFix) -> std::io::Result<()> {
    let Some(pos) = GpsColumns::from_fix(fix) else {
        return Ok(());
    };
    let (lat, lon) = (format!("{:.7}", pos.lat_deg), format!("{:.7}", pos.lon_deg));
    w.create_element("trkpt")
        .with_attribute(("lat", lat.as_str()))
        .with_attribute(("lon", lon.as_str()))
        .write_inner_content(|w| {
            // GPX 1.1 fixes the order: ele, time, ..., fix, sat, hdop.
            if let Some(alt_cm) = fix.alt_cm {
                let ele = format!("{:.2}", f64::from(alt_cm) / 100.0);
                w.create_element("ele")
                    .write_text_content(BytesText::new(&ele))?;
            }
            if let Some(utc) = fix.utc {
                let time = crate::time::iso8601(utc);
                w.create_element("time")
                    .write_text_content(BytesText::new(&time))?;
            }
            w.create_element("fix")
                .write_text_content(BytesText::new(pos.fix.as_str()))?;
            if let Some(sats) = fix.sats {
                w.create_element("sat")
                    .write_text_content(BytesText::new(&sats.to_string()))?;
            }
            if let Some(hdop) = fix.hdop_d {
                let hdop = format!("{:.1}", f64::from(hdop) / 10.0);
                w.create_element("hdop")
                    .write_text_content(BytesText::new(&hdop))?;
            }
            Ok(())
        })?;
    Ok(())
}
