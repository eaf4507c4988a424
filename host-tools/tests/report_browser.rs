//! `wobblog report`: the page of a campaign with wobbles, kicks, an alert,
//! markers, GPS and a damaged log, its numbers against the CLI's JSON, its
//! markup, and the page opened in headless Chromium (no console error,
//! every view and section there, zoom synchronised, screenshots). The
//! browser tests skip with a loud message only where Chromium is missing
//! (`hil-tests/install-tools.sh` installs it; on CI, `CI=true`, a missing
//! browser fails).

mod analysis_support;

use std::path::{Path, PathBuf};
use std::process::Command as Process;
use std::time::Instant;

use analysis_support::{kick_pass, standard_log, stdout_of, wobblog, write_log, Extras};
use serde_json::Value;

/// Kick passes of the campaign, and their speeds.
const PASSES: usize = 8;
/// The campaign's wobble speed and ring frequency.
const WOBBLE_MPS: f64 = 4.0;
const FREQ_HZ: f64 = 6.5;

/// The campaign: a ride with a growing wobble, an alert, two markers and
/// GPS (RUN00001), kick passes from 2 to 3.4 m/s (RUN00002...), and the
/// first ride again with a block damaged (RUN00010).
fn campaign() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    standard_log(&dir.path().join("RUN00001.WBL"));
    for i in 0..PASSES {
        let u = 2.0 + 1.4 * i as f64 / (PASSES - 1) as f64;
        let extras = Extras {
            gps: true,
            ..Extras::default()
        };
        let name = format!("RUN{:05}.WBL", i + 2);
        write_log(
            &dir.path().join(name),
            &kick_pass(u, WOBBLE_MPS, FREQ_HZ, i as u32),
            &extras,
        );
    }
    let damaged = dir.path().join("RUN00010.WBL");
    standard_log(&damaged);
    let mut bytes = std::fs::read(&damaged).unwrap();
    bytes[20 * 512 + 77] ^= 0x10;
    std::fs::write(&damaged, &bytes).unwrap();
    dir
}

/// `wobblog report ARGS -o DIR/report.html`, which must succeed; the page.
fn report(args: &[&std::ffi::OsStr], dir: &Path) -> (PathBuf, String) {
    let page = dir.join("report.html");
    stdout_of(wobblog().arg("report").args(args).arg("-o").arg(&page));
    let html = std::fs::read_to_string(&page).unwrap();
    (page, html)
}

/// The value of attribute `name` of the element with id `id`.
fn attribute<'a>(html: &'a str, id: &str, name: &str) -> &'a str {
    let tag_start = html.find(&format!("id=\"{id}\"")).expect(id);
    let tag = &html[tag_start..tag_start + html[tag_start..].find('>').unwrap()];
    let at = tag.find(&format!(" {name}=\"")).expect(name) + name.len() + 3;
    &tag[at..at + tag[at..].find('"').unwrap()]
}

/// The text of the ride view of `name`.
fn ride_view<'a>(html: &'a str, name: &str) -> &'a str {
    let heading = format!("<h2>{name}</h2>");
    let at = html.find(&heading).expect(name);
    let view_start = html[..at].rfind("<main").unwrap();
    &html[view_start..view_start + html[view_start..].find("</main>").unwrap()]
}

#[test]
fn the_pages_numbers_are_the_clis() {
    let dir = campaign();
    let logs = dir.path();
    let (_, html) = report(&[logs.as_os_str()], logs);
    let margin: Value =
        serde_json::from_str(&stdout_of(wobblog().arg("margin").arg(logs).arg("--json"))).unwrap();
    // The same number, to the last digit, as JSON prints it.
    let mps = margin["wobble_speed_mps"].as_f64().unwrap();
    assert_eq!(
        attribute(&html, "wobble-speed", "data-mps"),
        mps.to_string()
    );
    let lo = margin["ci95_mps"][0].as_f64().unwrap();
    assert_eq!(attribute(&html, "wobble-speed", "data-lo"), lo.to_string());
    assert!(html.contains(&format!("Predicted wobble speed {mps:.2} m/s")));
    assert!((mps - WOBBLE_MPS).abs() < 0.3, "{mps}");

    // Every run's row: episodes as `wobble --json` counts them, kicks as
    // `margin` takes them, the damage as `info --json` counts it.
    for entry in std::fs::read_dir(logs).unwrap() {
        let log = entry.unwrap().path();
        if log.extension().is_none_or(|e| e != "WBL") {
            continue;
        }
        let name = log.file_name().unwrap().to_str().unwrap();
        let wobble: Value =
            serde_json::from_str(&stdout_of(wobblog().arg("wobble").arg(&log).arg("--json")))
                .unwrap();
        let episodes = wobble["episodes"].as_array().unwrap();
        let row_start = html.find(&format!("\">{name}</a></td>")).expect(name);
        let row = &html[row_start..row_start + html[row_start..].find("</tr>").unwrap()];
        let unstable = episodes
            .iter()
            .filter(|e| e["stability"] == "unstable")
            .count();
        assert!(
            row.contains(&format!("<td>{} ({unstable})</td>", episodes.len())),
            "{name}: {row}"
        );
        let kicks = margin["kicks"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|k| k["log"].as_str() == log.to_str())
            .count();
        let info = analysis_support::info_json(&log);
        let view = ride_view(&html, name);
        for e in episodes {
            let text = format!(
                "{:.2} Hz, sigma {:+.2} 1/s",
                e["freq_hz"].as_f64().unwrap(),
                e["sigma_per_s"].as_f64().unwrap()
            );
            assert!(view.contains(&text), "{name}: {text}");
        }
        let lost = info["lost_blocks"].as_u64().unwrap();
        assert!(
            view.contains(&format!(
                "<tr><th>blocks lost from the file</th><td>{lost}</td></tr>"
            )),
            "{name}"
        );
        if name == "RUN00010.WBL" {
            assert!(lost > 0, "the damaged log lost no block");
            assert!(view.contains("<ul class=\"damage\"><li>"), "{view}");
            assert!(view.contains("class=\"ev-lost_blocks\""), "{view}");
        } else {
            assert!(view.contains("Nothing lost from the file."), "{name}");
        }
        let kick_cells = format!(
            "<td>{kicks}</td><td>{}</td>",
            info["alerts"].as_array().unwrap().len()
        );
        assert!(row.contains(&kick_cells), "{name}: {row}");
    }
}

/// Tags that have no end tag in HTML.
const VOID: [&str; 8] = ["meta", "br", "img", "input", "hr", "link", "wbr", "col"];

/// Checks that every element of `html` is closed in order (void elements
/// and self-closed SVG ones aside), that attributes are quoted, and that
/// script and style text never holds its end tag early.
fn check_markup(html: &str) {
    assert!(html.starts_with("<!DOCTYPE html>\n<html lang=\"en\">"));
    let mut open: Vec<String> = Vec::new();
    let mut rest = html["<!DOCTYPE html>".len()..].trim_start();
    while let Some(at) = rest.find('<') {
        rest = &rest[at..];
        if let Some(comment) = rest.strip_prefix("<!--") {
            rest = &comment[comment.find("-->").expect("an unclosed comment") + 3..];
            continue;
        }
        let end = rest.find('>').expect("an unclosed tag");
        let tag = &rest[1..end];
        rest = &rest[end + 1..];
        if let Some(name) = tag.strip_prefix('/') {
            let top = open.pop().unwrap_or_default();
            assert_eq!(top, name, "</{name}> closes <{top}>");
            continue;
        }
        let name: String = tag
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric())
            .collect::<String>();
        assert!(!name.is_empty(), "a bad tag <{tag}>");
        let attrs = &tag[name.len()..];
        assert_eq!(attrs.matches('"').count() % 2, 0, "<{tag}>");
        if tag.ends_with('/') || VOID.contains(&name.as_str()) {
            continue;
        }
        if name == "script" || name == "style" {
            let close = format!("</{name}>");
            let body_end = rest.find(&close).unwrap();
            rest = &rest[body_end + close.len()..];
            continue;
        }
        open.push(name);
    }
    assert!(open.is_empty(), "never closed: {open:?}");
}

#[test]
fn the_page_is_well_formed_and_self_contained() {
    let dir = campaign();
    let (_, html) = report(&[dir.path().as_os_str()], dir.path());
    check_markup(&html);
    // Nothing fetched: no external script, style, image or font.
    for outside in ["src=\"http", "href=\"http", "url(http", "@import"] {
        assert!(!html.contains(outside), "{outside}");
    }
    assert_eq!(html.matches("<main class=\"view\"").count(), 1 + PASSES + 2);
}

#[test]
fn an_unreadable_log_is_named_and_no_page_written() {
    let dir = campaign();
    let junk = dir.path().join("JUNK.WBL");
    std::fs::write(&junk, vec![0x55u8; 4096]).unwrap();
    let page = dir.path().join("out.html");
    let out = wobblog()
        .arg("report")
        .arg(dir.path())
        .arg("-o")
        .arg(&page)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("JUNK.WBL"), "{stderr}");
    assert!(!page.exists());
}

/// The Chromium to test with; `None`, loudly, where it is missing (a
/// failure on CI).
fn chromium() -> Option<PathBuf> {
    let found = std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|p| p.join("chromium"))
            .find(|p| p.is_file())
    });
    if found.is_none() {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "chromium is missing: hil-tests/install-tools.sh installs it"
        );
        eprintln!(
            "\n*** SKIPPED: the report's browser test needs chromium (hil-tests/install-tools.sh installs it) ***\n"
        );
    }
    found
}

/// Headless Chromium with a fresh profile, nothing reached over the
/// network, and the page's console on stderr.
fn headless(browser: &Path, profile: &Path) -> Process {
    let mut cmd = Process::new(browser);
    cmd.args([
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--hide-scrollbars",
        "--enable-logging=stderr",
        "--v=0",
    ])
    .arg(format!("--user-data-dir={}", profile.display()));
    cmd
}

/// How long a browser run may take before the test gives up on it.
const BROWSER_DEADLINE: std::time::Duration = std::time::Duration::from_secs(120);

/// Runs `cmd` to its end, its output collected through files (no pipe can
/// fill and stall it); a browser still running after [`BROWSER_DEADLINE`]
/// is killed and fails the test rather than hanging it.
fn finished(mut cmd: Process) -> std::process::Output {
    let files = tempfile::tempdir().unwrap();
    let (out, err) = (files.path().join("out"), files.path().join("err"));
    cmd.stdout(std::fs::File::create(&out).unwrap())
        .stderr(std::fs::File::create(&err).unwrap());
    let mut child = cmd.spawn().unwrap();
    let started = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if started.elapsed() > BROWSER_DEADLINE {
            let _ = child.kill();
            let _ = child.wait();
            panic!("the browser ran for over {BROWSER_DEADLINE:?}: {cmd:?}");
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    };
    std::process::Output {
        status,
        stdout: std::fs::read(out).unwrap(),
        stderr: std::fs::read(err).unwrap(),
    }
}

fn url(page: &Path, view: &str) -> String {
    format!("file://{}#{view}", page.display())
}

/// What the page's self-test wrote (see `assets/report.js`), and the
/// browser's stderr.
fn self_test(browser: &Path, page: &Path) -> (Value, String) {
    let profile = tempfile::tempdir().unwrap();
    let mut cmd = headless(browser, profile.path());
    cmd.arg("--virtual-time-budget=10000")
        .arg("--dump-dom")
        .arg(url(page, "selftest"));
    let out = finished(cmd);
    let dom = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let start = dom
        .find("<pre id=\"selftest\" hidden=\"\">")
        .expect("the self-test's output")
        + "<pre id=\"selftest\" hidden=\"\">".len();
    let text = &dom[start..start + dom[start..].find("</pre>").unwrap()];
    let text = text
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&");
    let v = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}: {text}\n{stderr}"));
    (v, stderr)
}

/// Lines of the browser's log that report the page's console errors or
/// uncaught exceptions.
fn console_errors(stderr: &str) -> Vec<&str> {
    stderr
        .lines()
        .filter(|l| l.contains("CONSOLE") && (l.contains("Uncaught") || l.contains("rror")))
        .collect()
}

/// A PNG screenshot of `view` of `page`, `size` wide and high, into `out`.
fn screenshot(browser: &Path, page: &Path, view: &str, size: (u32, u32), out: &Path) {
    let profile = tempfile::tempdir().unwrap();
    let mut cmd = headless(browser, profile.path());
    cmd.arg("--virtual-time-budget=5000")
        .arg(format!("--window-size={},{}", size.0, size.1))
        .arg(format!("--screenshot={}", out.display()))
        .arg(url(page, view));
    let status = finished(cmd);
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let png = std::fs::read(out).unwrap();
    assert!(png.starts_with(b"\x89PNG") && png.len() > 10_000, "{view}");
}

/// The sections each view must show, and have something in.
const CAMPAIGN_SECTIONS: [&str; 4] = ["wobble-speed", "runs", "margin-plot", "figure8"];
const RIDE_SECTIONS: [&str; 6] = [
    "signals",
    "spectrogram",
    "events",
    "track",
    "config",
    "damage",
];

#[test]
fn the_page_opens_in_chromium_with_every_view() {
    let Some(browser) = chromium() else {
        return;
    };
    let dir = campaign();
    let (page, _) = report(&[dir.path().as_os_str()], dir.path());
    let margin: Value = serde_json::from_str(&stdout_of(
        wobblog().arg("margin").arg(dir.path()).arg("--json"),
    ))
    .unwrap();
    let started = Instant::now();
    let (test, stderr) = self_test(&browser, &page);
    eprintln!("self-test in the browser: {:?}", started.elapsed());
    assert_eq!(test["errors"], Value::Array(vec![]), "{test}");
    assert!(console_errors(&stderr).is_empty(), "{stderr}");
    let views = test["views"].as_array().unwrap();
    assert_eq!(views.len(), 1 + PASSES + 2);
    assert_eq!(test["link_shows"], "ride-0", "{test}");
    let campaign = &views[0];
    assert_eq!(campaign["id"], "campaign");
    assert_eq!(campaign["sections"], serde_json::json!(CAMPAIGN_SECTIONS));
    let mps = margin["wobble_speed_mps"].as_f64().unwrap();
    let words = campaign["wobble_speed_text"].as_str().unwrap();
    assert!(words.contains(&format!("{mps:.2} m/s")), "{words}");
    for view in &views[1..] {
        assert_eq!(view["sections"], serde_json::json!(RIDE_SECTIONS), "{view}");
        // Zoomed to the last event, every chart of the run with it.
        let zoomed = view["zoomed"].as_array().unwrap();
        let (a, b) = (zoomed[0].as_f64().unwrap(), zoomed[1].as_f64().unwrap());
        assert!(a < b && b - a < 60.0, "{view}");
        // Four Figure 6 panels, the spectrogram, five more IMU panels.
        assert_eq!(view["charts"], 10, "{view}");
        assert_eq!(view["synced"], true, "{view}");
        assert!(view["events"].as_u64().unwrap() > 0, "{view}");
    }

    let shots = tempfile::tempdir().unwrap();
    let update = std::env::var_os("WOBBLOG_UPDATE_SCREENSHOTS").is_some();
    for (view, name, size) in [
        ("campaign", "report-campaign.png", (1400, 2300)),
        ("ride-0", "report-ride.png", (1400, 2000)),
        ("ride-9", "report-damaged.png", (1400, 2600)),
    ] {
        let out = shots.path().join(name);
        screenshot(&browser, &page, view, size, &out);
        if update {
            let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/images");
            std::fs::copy(&out, docs.join(name)).unwrap();
        }
    }
}

/// An hour at 100 Hz with GPS, an alert and markers: the page stays small
/// (display thinning) and opens and zooms without stalling. The figures
/// printed are those of `firmware/docs/benchmarks.md` (Report).
#[test]
fn an_hours_page_is_small_and_opens_and_zooms_quickly() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00001.WBL");
    let ride = analysis_support::Ride::new(3600.0, 5.0, 15.0, 2.0, 0.5);
    let extras = Extras {
        alerts_s: vec![(16.0, 17.5), (1800.0, 1803.0)],
        markers_s: vec![5.0, 1200.0, 2400.0],
        gps: true,
        ..Extras::default()
    };
    write_log(&log, &ride, &extras);
    let started = Instant::now();
    let (page, html) = report(&[log.as_os_str()], dir.path());
    let written = started.elapsed();
    let mb = html.len() as f64 / 1e6;
    eprintln!("one hour: page {mb:.2} MB, written in {written:?}");
    assert!(mb < 4.0, "{mb} MB");
    let Some(browser) = chromium() else {
        return;
    };
    let (test, stderr) = self_test(&browser, &page);
    assert_eq!(test["errors"], Value::Array(vec![]), "{test}");
    assert!(console_errors(&stderr).is_empty(), "{stderr}");
    let view = &test["views"][1];
    let (build, zoom) = (
        view["build_ms"].as_f64().unwrap(),
        view["zoom_ms"].as_f64().unwrap(),
    );
    eprintln!("one hour: ride view built in {build:.0} ms, zoom step {zoom:.0} ms");
    // Generous bounds for a loaded test machine: a stall is seconds.
    assert!(build < 3000.0 && zoom < 1000.0, "{view}");
}

#[test]
fn a_model_puts_figure_8_over_its_wobble_mode_and_its_fit_in_words() {
    let dir = campaign();
    let params =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("bicycle-model/params/test-bicycle.toml");
    let (_, html) = report(
        &[
            dir.path().as_os_str(),
            "--model".as_ref(),
            params.as_os_str(),
        ],
        dir.path(),
    );
    let margin: Value = serde_json::from_str(&stdout_of(
        wobblog()
            .arg("margin")
            .arg(dir.path())
            .arg("--model")
            .arg(&params)
            .arg("--json"),
    ))
    .unwrap();
    // The fitted model's answer as the JSON has it (none when the fitted
    // model's wobble never turns unstable).
    let model = margin["model"]["wobble_speed_mps"]
        .as_f64()
        .map_or("none".to_owned(), |v| format!("{v:.2} m/s"));
    let lo = margin["model"]["ci95_mps"][0]
        .as_f64()
        .map_or("none".to_owned(), |v| format!("{v:.2} m/s"));
    let words =
        format!("The model fitted to the kicks: wobble speed {model}, 95 % interval {lo} to");
    assert!(html.contains(&words), "{words}");
    assert!(html.contains("Figure 8: every episode over the model of test-bicycle.toml"));
    assert!(html.contains("wobble mode and measured episodes"));
}

#[test]
fn names_from_the_card_are_text_not_markup() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN<b>&\"1'.WBL");
    standard_log(&log);
    let (_, html) = report(&[log.as_os_str()], dir.path());
    check_markup(&html);
    assert!(html.contains("<h2>RUN&lt;b&gt;&amp;&quot;1&#39;.WBL</h2>"));
    // Raw only in the data block, which is script text, not markup.
    let data_start = html.find("<script type=\"application/json\"").unwrap();
    let data_end = data_start + html[data_start..].find("</script>").unwrap();
    assert!(html[data_start..data_end].contains("RUN<b>"));
    let markup = format!("{}{}", &html[..data_start], &html[data_end..]);
    assert!(!markup.contains("RUN<b>"));
}
