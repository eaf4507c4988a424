//! The page: HTML written from the campaign, with the charting library,
//! the page's script and style and the data inline, so the one file opens
//! anywhere without a network.

use std::fmt::Write;

use serde::Serialize;

use super::ride::{EventLine, RideView};
use super::spectrogram::Spectrogram;
use super::Campaign;
use crate::analysis::Stability;

/// uPlot, the charting library (MIT; version and licence in
/// `assets/uPlot-LICENSE.txt`).
const UPLOT_JS: &str = include_str!("../../assets/uPlot.iife.min.js");
const UPLOT_CSS: &str = include_str!("../../assets/uPlot.min.css");
const UPLOT_LICENSE: &str = include_str!("../../assets/uPlot-LICENSE.txt");
/// The page's own script and style.
const REPORT_JS: &str = include_str!("../../assets/report.js");
const REPORT_CSS: &str = include_str!("../../assets/report.css");

/// Text for HTML content and attribute values.
#[must_use]
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// A stretch drawn over the signals.
#[derive(Serialize)]
struct Band {
    a: f64,
    b: f64,
    kind: &'static str,
}

/// An instant drawn over the signals.
#[derive(Serialize)]
struct Mark {
    t: f64,
    kind: &'static str,
}

/// What the script needs of one run.
#[derive(Serialize)]
struct RideData<'a> {
    name: &'a str,
    channels: &'a [&'static str],
    t: &'a [f64],
    columns: &'a [Vec<Option<f64>>],
    bands: Vec<Band>,
    marks: Vec<Mark>,
    utc: &'a [crate::time::SyncPair],
    spectrogram: Option<&'a Spectrogram>,
    wheel_m: Option<f64>,
    band_hz: Option<(f64, f64)>,
}

impl<'a> RideData<'a> {
    fn of(r: &'a RideView) -> Self {
        let s = &r.summary;
        let end = s.frame_range_s.map_or(0.0, |f| f.1);
        let episodes = r.episodes.iter().map(|e| Band {
            a: e.onset_s,
            b: e.end_s,
            kind: match e.stability {
                Stability::Unstable => "unstable",
                Stability::Stable => "stable",
            },
        });
        let alerts = s.alerts.iter().map(|a| Band {
            a: a.on_s,
            b: a.off_s.unwrap_or(end),
            kind: "alert",
        });
        let first = s.frame_range_s.map_or(0.0, |f| f.0);
        let lost = s.losses.lost_blocks.iter().map(|g| Band {
            a: g.from_s.unwrap_or(first),
            b: g.to_s,
            kind: "lost",
        });
        let jumps = s
            .losses
            .time_jumps
            .iter()
            .filter(|(a, b)| a < b)
            .map(|&(a, b)| Band { a, b, kind: "jump" });
        let marks = r
            .events
            .iter()
            .filter_map(|e| {
                let kind = match e.kind.as_str() {
                    "marker" => "marker",
                    "kick" => "kick",
                    "fault" | "dropout" | "skipped" | "bad_record" | "out_of_range" => "fault",
                    _ => return None,
                };
                Some(Mark { t: e.t_s, kind })
            })
            .collect();
        Self {
            name: &r.name,
            channels: &r.channels,
            t: &r.series.t,
            columns: &r.series.columns,
            bands: episodes.chain(alerts).chain(lost).chain(jumps).collect(),
            marks,
            utc: &s.utc_syncs,
            spectrogram: r.spectrogram.as_ref(),
            wheel_m: r.wheel_m,
            band_hz: r.band_hz,
        }
    }
}

/// JSON to place inside a `<script>` element: `</` never appears, so no
/// name in the data can end the element.
fn script_json(value: &impl Serialize) -> Result<String, String> {
    serde_json::to_string(value)
        .map(|j| j.replace("</", "<\\/"))
        .map_err(|e| e.to_string())
}

/// Why the page could not be written.
#[derive(Debug)]
pub enum PageError {
    /// The data cannot be written as JSON.
    Data(String),
    /// The output failed.
    Write(std::io::Error),
}

/// Bytes gathered before they are written.
const PAGE_BUFFER: usize = 1 << 16;

/// The page as it is written: short pieces gathered, long ones (the
/// figures) written through, so the page is never held whole. The first
/// error of the output is kept and ends the writing.
struct Page<'a> {
    out: &'a mut dyn std::io::Write,
    buffer: String,
    error: Option<std::io::Error>,
}

impl Page<'_> {
    fn push_str(&mut self, s: &str) {
        let _ = self.write_str(s);
    }

    fn send(&mut self, bytes: &[u8]) {
        if self.error.is_none() {
            self.error = self.out.write_all(bytes).err();
        }
    }

    fn flush(&mut self) -> Result<(), PageError> {
        let buffer = std::mem::take(&mut self.buffer);
        self.send(buffer.as_bytes());
        match self.error.take() {
            Some(e) => Err(PageError::Write(e)),
            None => Ok(()),
        }
    }
}

impl Write for Page<'_> {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        if self.buffer.len() + s.len() > PAGE_BUFFER {
            let buffer = std::mem::take(&mut self.buffer);
            self.send(buffer.as_bytes());
            self.buffer = buffer;
            self.buffer.clear();
        }
        if s.len() > PAGE_BUFFER {
            self.send(s.as_bytes());
        } else {
            self.buffer.push_str(s);
        }
        Ok(())
    }
}

/// The page of `campaign`, whole.
///
/// # Errors
/// The data cannot be written as JSON.
pub fn render(campaign: &Campaign) -> Result<String, String> {
    let mut page = Vec::with_capacity(1 << 20);
    write(campaign, &mut page).map_err(|e| match e {
        PageError::Data(e) => e,
        PageError::Write(e) => e.to_string(),
    })?;
    String::from_utf8(page).map_err(|e| e.to_string())
}

/// Writes the page of `campaign` to `out` as it is made.
///
/// # Errors
/// The data cannot be written as JSON, or `out` failed.
pub fn write(campaign: &Campaign, out: &mut dyn std::io::Write) -> Result<(), PageError> {
    let mut o = Page {
        out,
        buffer: String::with_capacity(PAGE_BUFFER),
        error: None,
    };
    let title = match campaign.rides.as_slice() {
        [one] => format!("wobblog report: {}", one.name),
        rides => format!("wobblog report: {} runs", rides.len()),
    };
    let _ = write!(
        o,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <meta name=\"generator\" content=\"wobblog {}\">\n<title>{}</title>\n\
         <style>\n{UPLOT_CSS}\n{REPORT_CSS}\n</style>\n</head>\n<body>\n",
        env!("CARGO_PKG_VERSION"),
        escape(&title)
    );
    nav(&mut o, campaign, &title);
    campaign_view(&mut o, campaign);
    for (k, ride) in campaign.rides.iter().enumerate() {
        ride_view(&mut o, k, ride);
    }
    let data: Vec<RideData> = campaign.rides.iter().map(RideData::of).collect();
    let data = script_json(&data).map_err(PageError::Data)?;
    let _ = write!(
        o,
        "<pre id=\"selftest\" hidden></pre>\n\
         <footer>Made by wobblog {}. Charts: uPlot (MIT licence, in this file's source).</footer>\n\
         <script type=\"application/json\" id=\"report-data\">{data}</script>\n\
         <!--\n{}\n-->\n<script>\n{UPLOT_JS}\n</script>\n<script>\n{REPORT_JS}\n</script>\n</body>\n</html>\n",
        env!("CARGO_PKG_VERSION"),
        UPLOT_LICENSE.replace("--", "- -"),
    );
    o.flush()
}

fn nav(o: &mut Page<'_>, campaign: &Campaign, title: &str) {
    let _ = write!(
        o,
        "<header><h1>{}</h1><nav><a href=\"#campaign\">Campaign</a>",
        escape(title)
    );
    for (k, r) in campaign.rides.iter().enumerate() {
        let _ = write!(o, " <a href=\"#ride-{k}\">{}</a>", escape(&r.name));
    }
    o.push_str("</nav></header>\n");
}

fn opt(v: Option<f64>, unit: &str) -> String {
    v.map_or_else(|| "none".to_owned(), |v| format!("{v:.2} {unit}"))
}

fn campaign_view(o: &mut Page<'_>, c: &Campaign) {
    let m = &c.margin;
    let _ = write!(
        o,
        "<main class=\"view\" id=\"view-campaign\" data-view=\"campaign\">\n<section data-section=\"wobble-speed\">\
         <h2>Wobble speed of the campaign</h2>\n<p class=\"answer\" id=\"wobble-speed\" data-mps=\"{}\" \
         data-lo=\"{}\" data-hi=\"{}\" data-ride-below=\"{}\">{}</p>\n",
        json_number(m.wobble_speed_mps),
        json_number(m.ci95_mps[0]),
        json_number(m.ci95_mps[1]),
        json_number(m.ride_below_mps),
        escape(&speed_words(m)),
    );
    if !m.warnings.is_empty() {
        o.push_str("<ul class=\"warnings\">");
        for w in &m.warnings {
            let _ = write!(o, "<li>{}</li>", escape(w));
        }
        o.push_str("</ul>\n");
    }
    let _ = write!(
        o,
        "<details><summary>As <code>wobblog margin</code> says it</summary><pre>{}</pre></details>\n</section>\n",
        escape(&c.margin_words)
    );
    runs_table(o, c);
    figure(
        o,
        "margin-plot",
        "Damping trend: the kicks, the trend and where it crosses zero",
        &c.margin_svg,
    );
    let fig8 = match &c.model_file {
        Some(f) => format!("Figure 8: every episode over the model of {f}"),
        None => "Figure 8: every episode (give --model for the model's curve)".to_owned(),
    };
    figure(o, "figure8", &fig8, &c.modes_svg);
    o.push_str("</main>\n");
}

/// A number as JSON gives it (the shortest text that reads back the same),
/// empty for none.
fn json_number(v: Option<f64>) -> String {
    v.map(|v| serde_json::Number::from_f64(v).map_or(String::new(), |n| n.to_string()))
        .unwrap_or_default()
}

/// The answer in one sentence.
fn speed_words(m: &crate::cmd::margin::Report) -> String {
    let kicks = format!(
        "from {} ({} used, {} rejected)",
        crate::words::plural(m.kicks.len(), "kick"),
        m.kicks_used,
        m.kicks_rejected
    );
    let mut s = match (m.wobble_speed_mps, m.ci95_mps) {
        (Some(w), [lo, hi]) => format!(
            "Predicted wobble speed {w:.2} m/s, 95 % interval {} to {}, {kicks}.",
            opt(lo, "m/s"),
            hi.map_or_else(|| "unbounded".to_owned(), |v| format!("{v:.2} m/s"))
        ),
        (None, [Some(lo), _]) => {
            format!(
                "No predicted wobble speed: the kicks only say it is above {lo:.2} m/s, {kicks}."
            )
        }
        (None, _) => format!("No predicted wobble speed {kicks}."),
    };
    match m.ride_below_mps {
        Some(v) => {
            let _ = write!(s, " Ride below {v:.2} m/s.");
        }
        None => s.push_str(" No riding limit: stay at speeds already kicked."),
    }
    if let Some(model) = &m.model {
        let _ = write!(
            s,
            " The model fitted to the kicks: wobble speed {}, 95 % interval {} to {}.",
            opt(model.wobble_speed_mps, "m/s"),
            opt(model.ci95_mps[0], "m/s"),
            model.ci95_mps[1].map_or_else(|| "unbounded".to_owned(), |v| format!("{v:.2} m/s"))
        );
    }
    s
}

fn runs_table(o: &mut Page<'_>, c: &Campaign) {
    o.push_str(
        "<section data-section=\"runs\"><h2>Runs</h2>\n<table class=\"runs\"><thead><tr>\
         <th>run</th><th>start (UTC)</th><th>duration (s)</th><th>distance (m)</th>\
         <th>speed (m/s)</th><th>episodes (unstable)</th><th>wobble speed (m/s)</th>\
         <th>kicks</th><th>alerts</th><th>frames lost</th><th>damage</th></tr></thead><tbody>\n",
    );
    for (k, r) in c.rides.iter().enumerate() {
        let row = &r.row;
        let s = &r.summary;
        let damage = s.lost_blocks + s.damaged_blocks + s.bad_records + s.time_jumps;
        let _ = writeln!(
            o,
            "<tr{}><td><a href=\"#ride-{k}\">{}</a></td><td>{}</td><td>{:.1}</td><td>{:.0}</td>\
             <td>{:.2} to {:.2}</td><td>{} ({})</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            if damage > 0 { " class=\"damaged\"" } else { "" },
            escape(&r.name),
            escape(row.first_utc.as_deref().unwrap_or("-")),
            row.duration_s,
            row.distance_m,
            r.min_speed_mps,
            row.max_speed_mps,
            row.episodes,
            row.unstable_episodes,
            row.wobble_speed_mps.map_or("-".into(), |v| format!("{v:.2}")),
            c.kicks_of(r),
            s.alerts.len(),
            row.frames_lost,
            if damage == 0 {
                "none".to_owned()
            } else {
                format!("{} lost blocks, {} damaged, {} time jumps", s.lost_blocks, s.damaged_blocks, s.time_jumps)
            },
        );
    }
    o.push_str("</tbody></table></section>\n");
}

fn figure(o: &mut Page<'_>, section: &str, title: &str, svg: &Result<String, String>) {
    let _ = writeln!(
        o,
        "<section data-section=\"{section}\"><h2>{}</h2>",
        escape(title)
    );
    match svg {
        Ok(svg) => {
            let _ = writeln!(o, "<div class=\"figure\">{svg}</div>");
        }
        Err(e) => {
            let _ = writeln!(o, "<p class=\"note\">No figure: {}</p>", escape(e));
        }
    }
    o.push_str("</section>\n");
}

fn ride_view(o: &mut Page<'_>, k: usize, r: &RideView) {
    let s = &r.summary;
    let _ = write!(
        o,
        "<main class=\"view\" id=\"view-ride-{k}\" data-view=\"ride-{k}\" data-ride=\"{k}\" hidden>\n<h2>{}</h2>\n<p class=\"lead\">{}</p>\n",
        escape(&r.name),
        escape(&ride_lead(r)),
    );
    let _ = writeln!(
        o,
        "<div class=\"ride-grid\"><div><section data-section=\"signals\"><h3>Signals</h3>\
         <div class=\"controls\"><button data-act=\"out\">zoom out</button>\
         <button data-act=\"left\">&#8592; pan</button><button data-act=\"right\">pan &#8594;</button>\
         <button data-act=\"all\">whole run</button>\
         <label><input type=\"checkbox\" data-act=\"imu\"> rest of the IMU</label> \
         <span class=\"hint\">drag to zoom, wheel to zoom, shift+drag to pan, double-click for the whole run</span></div>\
         <p class=\"legend-key\"><span><i class=\"k-unstable\"></i>unstable wobble</span>\
         <span><i class=\"k-stable\"></i>stable (decaying) wobble</span><span><i class=\"k-alert\"></i>alert</span>\
         <span><i class=\"k-lost\"></i>data lost</span><span><i class=\"k-jump\"></i>clock jump</span>\
         <span><i class=\"k-marker\"></i>marker</span><span><i class=\"k-kick\"></i>kick</span>\
         <span><i class=\"k-fault\"></i>fault or damage</span></p>\
         <div class=\"charts\"></div><div class=\"imu-charts\"></div>{}</section>",
        if r.series.frames_out_of_order > 0 {
            format!(
                "<p class=\"note\">{} frames earlier than the frame before them (the clock jumped back) are not drawn.</p>",
                r.series.frames_out_of_order
            )
        } else {
            String::new()
        }
    );
    o.push_str(
        "<section data-section=\"spectrogram\"><h3>Steering spectrogram</h3>\
         <p class=\"hint\">Brightness: power of the steering angle (60 dB range). \
         Dashed: the detector's wobble band; white lines: the wheel's rotation and its second harmonic.</p>\
         <div class=\"spectrogram\"></div></section></div>\n",
    );
    events_list(o, r);
    o.push_str("</div>\n");
    o.push_str("<div class=\"ride-grid\"><section data-section=\"track\"><h3>GPS track</h3>");
    match &r.track_svg {
        Some(svg) => o.push_str(svg),
        None => o.push_str("<p class=\"note\">No GPS fix in this log.</p>"),
    }
    let _ = write!(
        o,
        "</section>\n<section data-section=\"config\"><h3>Configuration</h3>{}\
         <p class=\"hint\">Firmware {}, device {}, run {}, {} Hz.</p></section></div>\n",
        if s.config.is_empty() {
            "<p class=\"note\">No configuration lines in the log: the firmware's defaults.</p>"
                .to_owned()
        } else {
            format!(
                "<pre class=\"config\">{}</pre>",
                escape(&s.config.join("\n"))
            )
        },
        escape(s.firmware.as_deref().unwrap_or("?")),
        escape(s.device_id.as_deref().unwrap_or("?")),
        s.run.map_or("?".into(), |n| n.to_string()),
        s.sample_rate_hz.map_or("?".into(), |n| n.to_string()),
    );
    damage(o, r);
    o.push_str("</main>\n");
}

/// A run in one sentence.
fn ride_lead(r: &RideView) -> String {
    let row = &r.row;
    format!(
        "{:.1} s from {}, {:.0} m, {:.2} to {:.2} m/s; {}, {} unstable; wobble speed {}.",
        row.duration_s,
        row.first_utc.as_deref().unwrap_or("an unknown UTC time"),
        row.distance_m,
        r.min_speed_mps,
        row.max_speed_mps,
        crate::words::plural(row.episodes, "wobble episode"),
        row.unstable_episodes,
        opt(row.wobble_speed_mps, "m/s"),
    )
}

fn events_list(o: &mut Page<'_>, r: &RideView) {
    let _ = writeln!(
        o,
        "<section data-section=\"events\"><h3>Episodes and events</h3>\
         <p class=\"hint\">Click one to zoom there.</p><div class=\"events\"><table><thead><tr>\
         <th>t (s)</th><th>UTC</th><th>what</th><th>details</th></tr></thead><tbody>"
    );
    for e in &r.events {
        event_row(o, e);
    }
    o.push_str("</tbody></table></div>");
    let log_events = r.events.iter().filter(|e| e.kind != "episode").count();
    if r.events_total > log_events {
        let _ = write!(
            o,
            "<p class=\"note\">The first {log_events} of {} events; <code>wobblog events</code> lists them all.</p>",
            r.events_total
        );
    }
    o.push_str("</section>\n");
}

fn event_row(o: &mut Page<'_>, e: &EventLine) {
    let utc = escape(e.utc.as_deref().unwrap_or("-"));
    let _ = writeln!(
        o,
        "<tr class=\"ev-{}\" data-t=\"{}\" data-end=\"{}\" tabindex=\"0\"><td>{:.3}</td><td title=\"{utc}\">{}</td><td>{}</td><td>{}</td></tr>",
        escape(&e.kind),
        e.t_s,
        e.end_s.unwrap_or(e.t_s),
        e.t_s,
        // The time of day; the whole date in the cell's title.
        escape(utc.get(11..23).unwrap_or(&utc)),
        escape(&e.kind.replace('_', " ")),
        escape(&e.text),
    );
}

fn damage(o: &mut Page<'_>, r: &RideView) {
    let s = &r.summary;
    let _ = writeln!(
        o,
        "<section data-section=\"damage\"><h3>Damage and losses</h3>\
         <table class=\"counts\"><tbody>\
         <tr><th>frames</th><td>{}</td></tr><tr><th>frames dropped by the logger</th><td>{}</td></tr>\
         <tr><th>blocks lost from the file</th><td>{}</td></tr><tr><th>frames they held</th><td>{}</td></tr>\
         <tr><th>damaged blocks</th><td>{}</td></tr><tr><th>bytes skipped</th><td>{}</td></tr>\
         <tr><th>bad records</th><td>{}</td></tr><tr><th>time jumps</th><td>{}</td></tr>\
         <tr><th>GPS coverage</th><td>{:.1} %</td></tr></tbody></table>",
        s.samples,
        s.frames_dropped,
        s.lost_blocks,
        s.frames_lost,
        s.damaged_blocks,
        s.bytes_skipped,
        s.bad_records,
        s.time_jumps,
        s.gps_coverage_pct,
    );
    if r.damage.is_empty() {
        o.push_str("<p class=\"ok\">Nothing lost from the file.</p>");
    } else {
        o.push_str("<ul class=\"damage\">");
        for line in r.damage.iter().take(super::ride::MAX_EVENTS) {
            let _ = write!(o, "<li>{}</li>", escape(line));
        }
        o.push_str("</ul>");
    }
    o.push_str("</section>\n");
}
