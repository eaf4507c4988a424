//! `wobblog plot` and `wobblog wobble --plot`: the files are written, with
//! the panels, series, shading and markers the figures promise.

mod analysis_support;

use std::path::Path;

use analysis_support::{stdout_of, wobblog};
use base64::Engine;
use quick_xml::events::Event;
use wobblog::plot::modes::ZERO_LINE_COLOUR;
use wobblog::plot::timeplot::{
    ALERT_COLOUR, EPISODE_COLOUR, KICK_COLOUR, LINE_COLOUR, LOST_COLOUR, MARKER_COLOUR,
    MIN_SPAN_PX, PANELS,
};
use wobblog::plot::FONT;

fn hex(c: plotters::style::RGBColor) -> String {
    format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
}

/// Elements of `svg` of kind `tag` whose attributes mention `colour`.
fn count(svg: &str, tag: &str, colour: &str) -> usize {
    svg.split('<')
        .filter(|e| e.starts_with(tag) && e.to_uppercase().contains(colour))
        .count()
}

/// The text of every `<text>` element of `svg`.
fn texts(svg: &str) -> Vec<&str> {
    svg.split("<text")
        .skip(1)
        .filter_map(|e| Some(e[e.find('>')? + 1..e.find("</text>")?].trim()))
        .collect()
}

/// Reads `svg` with an XML parser and checks that it carries the bundled
/// font: a `<style>` with an `@font-face` whose `data:` URI decodes to the
/// committed TrueType file, and every `<text>` element in that family.
/// Returns the number of text elements.
fn assert_font_embedded(svg: &str) -> usize {
    let mut reader = quick_xml::Reader::from_str(svg);
    let (mut in_style, mut css, mut texts) = (false, String::new(), 0);
    loop {
        match reader.read_event().unwrap() {
            Event::Start(e) if e.name().as_ref() == b"style" => in_style = true,
            Event::End(e) if e.name().as_ref() == b"style" => in_style = false,
            Event::Text(t) if in_style => css.push_str(&t.decode().unwrap()),
            Event::Start(e) if e.name().as_ref() == b"text" => {
                texts += 1;
                let family = e.try_get_attribute("font-family").unwrap().unwrap();
                assert_eq!(family.unescape_value().unwrap(), FONT);
            }
            Event::Eof => break,
            _ => {}
        }
    }
    assert!(
        css.contains(&format!("font-family: \"{FONT}\"")),
        "{css:.200}"
    );
    let uri = "url(\"data:font/ttf;base64,";
    let start = css.find(uri).expect("no data URI") + uri.len();
    let data = &css[start..start + css[start..].find('"').unwrap()];
    let ttf = base64::engine::general_purpose::STANDARD
        .decode(data)
        .unwrap();
    let bundled = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/DejaVuSans.ttf");
    assert!(
        ttf == std::fs::read(bundled).unwrap(),
        "not the bundled font"
    );
    texts
}

#[test]
fn every_svg_carries_the_bundled_font() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    analysis_support::standard_log(&log);
    let fig6 = plot_svg(&log, &dir.path().join("fig6.svg"), &[]);
    assert!(assert_font_embedded(&fig6) > 20);
    let fig8 = dir.path().join("fig8.svg");
    wobblog()
        .args(["wobble", "--plot"])
        .arg(&fig8)
        .arg(&log)
        .assert()
        .success();
    assert!(assert_font_embedded(&std::fs::read_to_string(&fig8).unwrap()) > 20);
    let params =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("bicycle-model/params/test-bicycle.toml");
    let eig = dir.path().join("eig.svg");
    wobblog()
        .args(["model", "plot"])
        .arg(&params)
        .args(["--speeds", "0:8:1", "-o"])
        .arg(&eig)
        .assert()
        .success();
    assert!(assert_font_embedded(&std::fs::read_to_string(&eig).unwrap()) > 10);
}

fn plot_svg(log: &Path, out: &Path, extra: &[&str]) -> String {
    wobblog()
        .arg("plot")
        .arg(log)
        .arg("-o")
        .arg(out)
        .args(extra)
        .assert()
        .success();
    std::fs::read_to_string(out).unwrap()
}

#[test]
fn figure_6_has_four_panels_alerts_and_markers() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    analysis_support::standard_log(&log);
    let svg = plot_svg(&log, &dir.path().join("fig6.svg"), &[]);
    let labels = texts(&svg);
    for panel in PANELS {
        assert!(labels.contains(&panel), "no panel {panel:?} in {labels:?}");
    }
    // One line per panel (the log has no gaps), one shaded alert and two
    // markers in each of the four panels, and one of each in the key.
    assert_eq!(count(&svg, "polyline", &hex(LINE_COLOUR)), 4);
    assert_eq!(count(&svg, "rect", &hex(ALERT_COLOUR)), 4 + 1);
    assert_eq!(count(&svg, "polyline", &hex(MARKER_COLOUR)), 8 + 1);
    assert!(labels.contains(&"wobble alert (on board)"), "{labels:?}");
    assert!(labels.contains(&"rider marker"), "{labels:?}");
    // The host's wobble episode (the ride's one wobble), shaded and keyed.
    assert_eq!(count(&svg, "rect", &hex(EPISODE_COLOUR)), 4 + 1);
    assert!(labels.contains(&"wobble episode (host)"), "{labels:?}");
    assert!(
        !labels.contains(&"data lost (missing blocks)"),
        "{labels:?}"
    );
    assert!(
        labels
            .iter()
            .all(|l| !l.starts_with("-0") || l.starts_with("-0.")),
        "{labels:?}"
    );
    assert!(!labels.contains(&"-0"), "{labels:?}");
}

#[test]
fn lost_blocks_are_shaded_and_keyed() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    analysis_support::standard_log(&log);
    let mut bytes = std::fs::read(&log).unwrap();
    bytes[40 * 512 + 100] ^= 0x40;
    std::fs::write(&log, &bytes).unwrap();
    let svg = plot_svg(&log, &dir.path().join("lost.svg"), &[]);
    assert_eq!(count(&svg, "rect", &hex(LOST_COLOUR)), 4 + 1);
    assert!(texts(&svg).contains(&"data lost (missing blocks)"));
}

#[test]
fn utc_axis_is_labelled_from_the_sync_pairs() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    analysis_support::standard_log(&log);
    let svg = plot_svg(
        &log,
        &dir.path().join("utc.svg"),
        &["--utc", "--from", "2020-03-18T10:00:10Z", "--to", "15"],
    );
    let labels = texts(&svg);
    assert!(labels.contains(&"UTC (hh:mm:ss)"), "{labels:?}");
    // Five seconds: a tick every whole second.
    assert!(labels.contains(&"10:00:12"), "{labels:?}");
    assert!(
        labels.contains(
            &"RUN00003.WBL: 10.0 to 15.0 s (UTC 2020-03-18 10:00:10.000 to 10:00:15.000)"
        ),
        "{labels:?}"
    );
    // A short window: ticks at round UTC times, labelled below the second,
    // each once.
    let svg = plot_svg(
        &log,
        &dir.path().join("short.svg"),
        &["--utc", "--from", "10.03", "--to", "11.53"],
    );
    let ticks: Vec<f64> = texts(&svg)
        .into_iter()
        .filter_map(|t| t.strip_prefix("10:00:"))
        .filter(|t| t.contains('.'))
        .map(|t| t.parse().unwrap())
        .collect();
    // The same ticks on each of the four panels.
    assert!(ticks.len() >= 4 * 5, "{ticks:?}");
    let distinct: std::collections::BTreeSet<i64> =
        ticks.iter().map(|t| (t * 100.0).round() as i64).collect();
    assert_eq!(distinct.len() * 4, ticks.len(), "{ticks:?}");
    for t in &distinct {
        assert_eq!(t % 5, 0, "a tick at a round UTC time: {t}");
        assert!((1003..=1153).contains(t), "{t}");
    }
    // Without GPS, --utc has nothing to go by.
    let bare = dir.path().join("BARE.WBL");
    analysis_support::write_log(
        &bare,
        &analysis_support::Ride::new(5.0, 5.0, 0.0, 0.0, 0.0),
        &analysis_support::Extras::default(),
    );
    let out = wobblog()
        .arg("plot")
        .arg(&bare)
        .args(["--utc", "-o"])
        .arg(dir.path().join("bare.svg"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no UTC"));
}

#[test]
fn time_window_keeps_only_what_falls_in_it() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    analysis_support::standard_log(&log);
    let svg = plot_svg(
        &log,
        &dir.path().join("w.svg"),
        &["--from", "8", "--to", "15"],
    );
    assert_eq!(count(&svg, "rect", &hex(ALERT_COLOUR)), 0);
    assert_eq!(count(&svg, "polyline", &hex(MARKER_COLOUR)), 0);
    assert!(texts(&svg).contains(&"RUN00003.WBL: 8.0 to 15.0 s"));
    let svg = plot_svg(
        &log,
        &dir.path().join("w2.svg"),
        &["--from", "15", "--to", "21"],
    );
    assert_eq!(count(&svg, "rect", &hex(ALERT_COLOUR)), 4 + 1);
    assert_eq!(count(&svg, "polyline", &hex(MARKER_COLOUR)), 4 + 1);
}

#[test]
fn png_is_written_at_the_figure_size() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    analysis_support::standard_log(&log);
    let png = dir.path().join("fig6.png");
    wobblog()
        .arg("plot")
        .arg(&log)
        .arg("-o")
        .arg(&png)
        .assert()
        .success();
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    let be = |i: usize| u32::from_be_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    assert_eq!((be(16), be(20)), (1200, 40 + 4 * 220));
    // Text was rendered: a plot without glyphs would be far smaller.
    assert!(bytes.len() > 20_000, "{} bytes", bytes.len());
}

#[test]
fn figure_8_has_a_dot_per_episode_and_a_legend_per_run() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("A.WBL");
    let b = dir.path().join("B.WBL");
    analysis_support::standard_log(&a);
    // Another ride (a byte-identical copy would be one input).
    let (_, extras) = analysis_support::standard_log(&b);
    let ride = analysis_support::Ride::new(30.0, 5.0, 15.0, 2.0, 0.4);
    analysis_support::write_log(&b, &ride, &extras);
    let svg_path = dir.path().join("modes.svg");
    let json = stdout_of(
        wobblog()
            .args(["wobble", "--json", "--plot"])
            .arg(&svg_path)
            .arg(&a)
            .arg(&b),
    );
    let episodes: usize = json
        .lines()
        .map(|l| {
            serde_json::from_str::<serde_json::Value>(l).unwrap()["episodes"]
                .as_array()
                .unwrap()
                .len()
        })
        .sum();
    assert!(episodes >= 2);
    let svg = std::fs::read_to_string(&svg_path).unwrap();
    // Each episode in the three panels, and a marker per run in the key.
    assert_eq!(svg.matches("<circle").count(), 3 * episodes + 2);
    // The stability boundary: sigma = 0, upright in the complex plane and
    // level in the sigma-against-speed panel.
    let zero_lines: Vec<Vec<(f64, f64)>> = svg
        .split('<')
        .filter(|e| e.starts_with("polyline") && e.to_uppercase().contains(&hex(ZERO_LINE_COLOUR)))
        .map(|e| {
            let points = e
                .split("points=\"")
                .nth(1)
                .unwrap()
                .split('"')
                .next()
                .unwrap();
            points
                .split_whitespace()
                .map(|p| {
                    let (x, y) = p.split_once(',').unwrap();
                    (x.parse().unwrap(), y.parse().unwrap())
                })
                .collect()
        })
        .collect();
    assert_eq!(zero_lines.len(), 2, "{zero_lines:?}");
    let upright = |l: &Vec<(f64, f64)>| l.iter().all(|p| p.0 == l[0].0) && l[0].1 != l[1].1;
    let level = |l: &Vec<(f64, f64)>| l.iter().all(|p| p.1 == l[0].1) && l[0].0 != l[1].0;
    assert!(upright(&zero_lines[0]), "{zero_lines:?}");
    assert!(level(&zero_lines[1]), "{zero_lines:?}");
    let labels = texts(&svg);
    for label in [
        "A.WBL",
        "B.WBL",
        wobblog::plot::modes::X_LABEL,
        wobblog::plot::modes::Y_LABEL,
        wobblog::plot::modes::SPEED_LABEL,
    ] {
        assert!(labels.contains(&label), "no {label:?} in {labels:?}");
    }
}

#[test]
fn figure_8_key_skips_runs_without_episodes() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("A.WBL");
    analysis_support::standard_log(&a);
    let quiet = dir.path().join("QUIET.WBL");
    let calm = analysis_support::Ride::new(30.0, 5.0, 15.0, 2.0, 0.5);
    let calm = analysis_support::Ride {
        steer_deg: calm.roll_deg.iter().map(|r| 2.0 * r.to_radians()).collect(),
        ..calm
    };
    analysis_support::write_log(&quiet, &calm, &analysis_support::Extras::default());
    let svg_path = dir.path().join("modes.svg");
    wobblog()
        .args(["wobble", "--plot"])
        .arg(&svg_path)
        .arg(&a)
        .arg(&quiet)
        .assert()
        .success();
    let svg = std::fs::read_to_string(&svg_path).unwrap();
    let labels = texts(&svg);
    assert!(labels.contains(&"A.WBL"), "{labels:?}");
    assert!(!labels.contains(&"QUIET.WBL"), "{labels:?}");
}

#[test]
fn bad_requests_are_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    analysis_support::standard_log(&log);
    let jpg = dir.path().join("x.jpg");
    wobblog()
        .arg("plot")
        .arg(&log)
        .arg("-o")
        .arg(&jpg)
        .assert()
        .code(2);
    let svg = dir.path().join("x.svg");
    wobblog()
        .arg("plot")
        .arg(&log)
        .arg("-o")
        .arg(&svg)
        .args(["--from", "9", "--to", "3"])
        .assert()
        .code(2);
    // A window outside the run is a failure about the log, not a panic.
    wobblog()
        .arg("plot")
        .arg(&log)
        .arg("-o")
        .arg(&svg)
        .args(["--from", "500"])
        .assert()
        .code(1);
}

/// The README's example figures, drawn from the synthetic ride (Figure 6)
/// and from it plus its stable kicks (Figure 8). Written to a temporary
/// directory; with `WOBBLOG_UPDATE_DOC_IMAGES` set, into `docs/images/`.
#[test]
fn example_images() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = if std::env::var_os("WOBBLOG_UPDATE_DOC_IMAGES").is_some() {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/images")
    } else {
        dir.path().to_path_buf()
    };
    let log = dir.path().join("RUN00003.WBL");
    analysis_support::standard_log(&log);
    let fig6 = out_dir.join("figure6.png");
    wobblog()
        .arg("plot")
        .arg(&log)
        .arg("-o")
        .arg(&fig6)
        .args(["--from", "10", "--to", "22"])
        .assert()
        .success();
    let fig8 = out_dir.join("figure8.png");
    let corpus = analysis_support::corpus_dir();
    let mut logs = vec![log];
    for name in [
        "wobble_g1.0",
        "wobble_f8.3",
        "ride_two_wobbles",
        "ride_kicks",
        "ride_potholes_kerbs",
    ] {
        let csv = corpus.join(format!("{name}.csv"));
        if csv.exists() {
            let wbl = dir.path().join(format!("{name}.wbl"));
            wobblog()
                .args(["encode", "--csv"])
                .arg(&csv)
                .arg("-o")
                .arg(&wbl)
                .assert()
                .success();
            logs.push(wbl);
        }
    }
    wobblog()
        .arg("wobble")
        .arg("--plot")
        .arg(&fig8)
        .args(&logs)
        .assert()
        .success();
    assert!(std::fs::metadata(&fig6).unwrap().len() > 20_000);
    assert!(std::fs::metadata(&fig8).unwrap().len() > 20_000);
}

#[test]
fn a_log_of_one_frame_is_plotted() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("one.csv");
    std::fs::write(&csv, "t_s,steer_deg\n0,1\n").unwrap();
    let log = dir.path().join("one.WBL");
    stdout_of(
        wobblog()
            .args(["encode", "--csv"])
            .arg(&csv)
            .arg("-o")
            .arg(&log),
    );
    for name in ["one.png", "one.svg"] {
        let out = dir.path().join(name);
        stdout_of(wobblog().arg("plot").arg(&log).arg("-o").arg(&out));
        assert!(std::fs::metadata(&out).unwrap().len() > 1000, "{name}");
    }
    // The frame's value in each panel, as a dot (a line of one point
    // would draw nothing).
    let svg = std::fs::read_to_string(dir.path().join("one.svg")).unwrap();
    assert_eq!(svg.matches("<circle").count(), PANELS.len(), "{svg:.300}");
}

/// The widths of the `<rect>` elements of `svg` in `colour`, px.
fn rect_widths(svg: &str, colour: &str) -> Vec<f64> {
    svg.split('<')
        .filter(|e| e.starts_with("rect") && e.to_uppercase().contains(colour))
        .filter_map(|e| {
            let at = e.find("width=\"")? + 7;
            e[at..e[at..].find('"')? + at].parse().ok()
        })
        .collect()
}

/// A 10 ms alert on a 30 s figure is drawn at least [`MIN_SPAN_PX`] wide,
/// not as a hairline; the board's kick records are ticked and keyed.
#[test]
fn short_spans_stay_visible_and_kick_records_are_ticked() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00004.WBL");
    let ride = analysis_support::Ride::new(30.0, 5.0, 0.0, 0.0, 0.0);
    let extras = analysis_support::Extras {
        alerts_s: vec![(10.0, 10.01)],
        records: vec![
            analysis_support::kick_record(5.0, Some(4000)),
            analysis_support::kick_record(20.0, None),
        ],
        ..Default::default()
    };
    analysis_support::write_log(&log, &ride, &extras);
    let svg = plot_svg(&log, &dir.path().join("short.svg"), &[]);
    let widths = rect_widths(&svg, &hex(ALERT_COLOUR));
    // Four panels' spans, then the key's swatch (16 px).
    assert_eq!(widths.len(), 5, "{widths:?}");
    assert!(
        widths[..4].iter().all(|w| *w >= MIN_SPAN_PX - 0.5),
        "{widths:?}"
    );
    assert_eq!(count(&svg, "polyline", &hex(KICK_COLOUR)), 2 * 4 + 1);
    assert!(texts(&svg).contains(&"kick record (board)"));
}
