//! `wobblog gpx`: the run's GPS track as GPX 1.1, for maps and GIS tools.

use std::io::Write;
use std::path::{Path, PathBuf};

use quick_xml::events::{BytesDecl, BytesEnd, BytesStart, BytesText, Event};
use quick_xml::Writer;
use wobble_core::format::{Event as LogEvent, GpsFix, Record};

use crate::output::Output;
use crate::reader::read_log_try;
use crate::rows::GpsColumns;
use crate::time::{utc_ms_at, SyncPair, TimeWindow, WindowArgs};
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
    // One track into one named output: a folder is refused with its logs.
    crate::cmd::logs::one_log(&args.log, "gpx", "write one track per log")?;
    let mut out = Output::create_or_stdout(args.output.as_deref(), &[&args.log])?;
    // Control characters are not XML: a name holding them is escaped.
    let name = args.log.file_stem().map_or_else(String::new, |s| {
        crate::text::escape_controls(&s.to_string_lossy()).into_owned()
    });
    let mut points = 0usize;
    let mut gpx = Gpx::new(&mut out, &name);
    let walked = track(&args.log, args.window.window(), |step| {
        points += usize::from(matches!(step, Step::Point(..)));
        gpx.step(step)
    })?;
    walked
        .and_then(|()| gpx.finish())
        .map_err(|e| out.error(e))?;
    if points == 0 {
        eprintln!(
            "wobblog: {}: warning: no GPS fix with a position; the track is empty",
            crate::text::shown(&args.log)
        );
    }
    out.commit()
}

/// What the track does next.
#[derive(Debug)]
pub enum Step<'a> {
    /// A fix with a position, in the current segment, and its UTC (ms
    /// since 1970): the fix's own, else through the log's sync pairs as
    /// `decode`'s `utc` column gives it.
    Point(&'a GpsFix, Option<i64>),
    /// The current segment ends: a gap in the fixes or in the file.
    Break,
}

/// Walks the fixes with a position inside `window`, in file order, a
/// [`Step::Break`] between segments, without holding them. An error from
/// `visit` ends the walk and is the inner result.
///
/// # Errors
/// The log cannot be read, or a window was given and holds no fix.
pub fn track<E>(
    log: &Path,
    window: TimeWindow,
    mut visit: impl FnMut(Step<'_>) -> Result<(), E>,
) -> Result<Result<(), E>, CliError> {
    window.check_order(log)?;
    // The time of the open segment's last point.
    let mut last_us: Option<u64> = None;
    let (mut points, mut span_s, mut has_utc) = (0u64, None::<(f64, f64)>, false);
    // The latest sync pair, for fixes without a UTC of their own.
    let mut sync: Vec<SyncPair> = Vec::new();
    let walked = read_log_try(log, |event| {
        if let LogEvent::Record(Record::UtcSync(pair)) = &event {
            if let Ok(ms) = i64::try_from(pair.unix_ms) {
                sync = vec![(pair.t_us as f64 / 1e6, ms)];
            }
        }
        let LogEvent::Record(Record::Gps(fix)) = event else {
            // A block lost from the file may have held fixes.
            if matches!(event, LogEvent::Gap(_)) && last_us.take().is_some() {
                visit(Step::Break)?;
            }
            return Ok(());
        };
        let t_s = fix.t_us as f64 / 1e6;
        let utc_ms = fix
            .utc
            .and_then(|u| i64::try_from(u.unix_ms()).ok())
            .or_else(|| utc_ms_at(&sync, t_s));
        let positioned = GpsColumns::from_fix(&fix).is_some();
        if positioned {
            has_utc |= utc_ms.is_some();
            span_s = Some(span_s.map_or((t_s, t_s), |(a, b): (f64, f64)| (a.min(t_s), b.max(t_s))));
        }
        if !positioned || !window.contains(t_s, utc_ms) {
            if last_us.take().is_some() {
                visit(Step::Break)?;
            }
            return Ok(());
        }
        if last_us.is_some_and(|t| fix.t_us.saturating_sub(t) > SEGMENT_GAP_US) {
            visit(Step::Break)?;
        }
        last_us = Some(fix.t_us);
        points += 1;
        visit(Step::Point(&fix, utc_ms))
    })?;
    if walked.is_ok() && points == 0 && !window.is_all() {
        return Err(window.selects_nothing(log, "GPS fixes with a position", span_s, has_utc));
    }
    Ok(walked)
}

/// A GPX 1.1 document of one track, written as its points come; nothing
/// is written before the first step (or [`Gpx::finish`]), so a log that
/// cannot be opened leaves no output.
pub struct Gpx<'n, W: Write> {
    w: Writer<W>,
    /// The track's name, until the document's start is written.
    unstarted: Option<&'n str>,
    in_segment: bool,
}

impl<'n, W: Write> Gpx<'n, W> {
    /// A track named `name`, to be written to `out`.
    pub fn new(out: W, name: &'n str) -> Self {
        Self {
            w: Writer::new_with_indent(out, b' ', 1),
            unstarted: Some(name),
            in_segment: false,
        }
    }

    fn start(&mut self) -> std::io::Result<()> {
        let Some(name) = self.unstarted.take() else {
            return Ok(());
        };
        let w = &mut self.w;
        w.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))?;
        let gpx = BytesStart::new("gpx").with_attributes([
            ("version", "1.1"),
            ("creator", concat!("wobblog ", env!("CARGO_PKG_VERSION"))),
            ("xmlns", "http://www.topografix.com/GPX/1/1"),
        ]);
        w.write_event(Event::Start(gpx))?;
        w.write_event(Event::Start(BytesStart::new("trk")))?;
        w.create_element("name")
            .write_text_content(BytesText::new(name))?;
        Ok(())
    }

    /// Writes the next step of the track.
    ///
    /// # Errors
    /// Writing failed.
    pub fn step(&mut self, step: Step<'_>) -> std::io::Result<()> {
        self.start()?;
        match step {
            Step::Point(fix, utc_ms) => {
                if !self.in_segment {
                    self.w
                        .write_event(Event::Start(BytesStart::new("trkseg")))?;
                    self.in_segment = true;
                }
                write_point(&mut self.w, fix, utc_ms)
            }
            Step::Break => self.end_segment(),
        }
    }

    fn end_segment(&mut self) -> std::io::Result<()> {
        if std::mem::take(&mut self.in_segment) {
            self.w.write_event(Event::End(BytesEnd::new("trkseg")))?;
        }
        Ok(())
    }

    /// Ends the document and flushes it.
    ///
    /// # Errors
    /// Writing failed.
    pub fn finish(mut self) -> std::io::Result<()> {
        self.start()?;
        self.end_segment()?;
        self.w.write_event(Event::End(BytesEnd::new("trk")))?;
        self.w.write_event(Event::End(BytesEnd::new("gpx")))?;
        self.w.into_inner().flush()
    }
}

fn write_point<W: Write>(
    w: &mut Writer<W>,
    fix: &GpsFix,
    utc_ms: Option<i64>,
) -> std::io::Result<()> {
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
            // The fix's own time keeps a leap second (23:59:60).
            let time = fix
                .utc
                .map(crate::time::iso8601)
                .or_else(|| utc_ms.and_then(crate::time::iso8601_unix_ms));
            if let Some(time) = time {
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
