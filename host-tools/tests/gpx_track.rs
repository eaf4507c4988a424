//! `wobblog gpx`: the GPS track as GPX 1.1, split where the fix was lost.

mod analysis_support;

use analysis_support::{stdout_of, wobblog, Extras, Ride, LON_DEG, START_LAT_DEG};
use quick_xml::events::Event;
use quick_xml::Reader;

/// Track points of each segment: (lat, lon, has time, has ele).
fn segments(gpx: &str) -> Vec<Vec<(f64, f64, bool, bool)>> {
    let mut reader = Reader::from_str(gpx);
    let mut out: Vec<Vec<(f64, f64, bool, bool)>> = Vec::new();
    let mut inside = String::new();
    loop {
        match reader.read_event().unwrap() {
            Event::Start(e) => {
                let name = String::from_utf8(e.name().as_ref().to_vec()).unwrap();
                match name.as_str() {
                    "trkseg" => out.push(Vec::new()),
                    "trkpt" => {
                        let attr = |k: &str| -> f64 {
                            let a = e.try_get_attribute(k).unwrap().unwrap();
                            std::str::from_utf8(&a.value).unwrap().parse().unwrap()
                        };
                        out.last_mut()
                            .unwrap()
                            .push((attr("lat"), attr("lon"), false, false));
                    }
                    _ => {}
                }
                inside = name;
            }
            Event::Text(_) => {
                if let Some(p) = out.last_mut().and_then(|s| s.last_mut()) {
                    p.2 |= inside == "time";
                    p.3 |= inside == "ele";
                }
            }
            Event::Eof => return out,
            _ => {}
        }
    }
}

#[test]
fn track_has_every_fix_and_splits_at_the_outage() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    let (ride, extras) = analysis_support::standard_log(&log);
    let gpx = stdout_of(wobblog().arg("gpx").arg(&log));
    assert!(gpx.contains("http://www.topografix.com/GPX/1/1"));
    let segs = segments(&gpx);
    assert_eq!(segs.len(), 2, "one segment before the outage, one after");
    let expected = (0..ride.t_s.len())
        .filter_map(|i| analysis_support::gps_fix(&ride, i, &extras))
        .filter(|f| f.lat_e7.is_some())
        .count();
    let points: Vec<_> = segs.iter().flatten().collect();
    assert_eq!(points.len(), expected);
    assert!(
        points.iter().all(|p| p.2 && p.3),
        "every point has time and elevation"
    );
    assert!(points.iter().all(|p| (p.1 - LON_DEG).abs() < 1e-7));
    // Due north at 5 m/s: latitude grows steadily from the start.
    assert!((points[0].0 - START_LAT_DEG).abs() < 1e-6);
    assert!(points.windows(2).all(|w| w[1].0 > w[0].0));
}

#[test]
fn log_without_gps_gives_an_empty_track_and_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("NOGPS.WBL");
    analysis_support::write_log(
        &log,
        &Ride::new(5.0, 4.0, 0.0, 0.0, 0.0),
        &Extras::default(),
    );
    let gpx_path = dir.path().join("t.gpx");
    let out = wobblog()
        .arg("gpx")
        .arg(&log)
        .arg("-o")
        .arg(&gpx_path)
        .output()
        .unwrap();
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("no GPS fix"));
    assert!(segments(&std::fs::read_to_string(&gpx_path).unwrap()).is_empty());
}

#[test]
fn a_log_that_cannot_be_read_leaves_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = wobblog()
        .arg("gpx")
        .arg(dir.path().join("MISSING.WBL"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("MISSING.WBL"));
}

#[test]
fn the_track_is_walked_as_read_and_stops_at_the_first_failed_write() {
    use wobblog::cmd::gpx::{track, Step};
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    analysis_support::standard_log(&log);
    let walk = |stop_after: usize| {
        let (mut points, mut breaks) = (0, 0);
        let walked = track(&log, Default::default(), |step| {
            match step {
                Step::Point(..) => points += 1,
                Step::Break => breaks += 1,
            }
            if points == stop_after {
                Err(points)
            } else {
                Ok(())
            }
        })
        .unwrap();
        (walked, points, breaks)
    };
    let (whole, points, breaks) = walk(usize::MAX);
    assert_eq!(whole, Ok(()));
    assert_eq!(breaks, 1, "one break, at the outage");
    assert!(points > 100, "{points} points");
    let (stopped, seen, _) = walk(3);
    assert_eq!(
        (stopped, seen),
        (Err(3), 3),
        "nothing visited after the error"
    );
}

/// A log whose only fixes are at `times_s`, each 1e-4 degrees further north.
fn log_with_fixes(path: &std::path::Path, times_s: &[f64]) {
    use wobble_core::format::{FixMode, GpsFix, Record};
    let records = times_s
        .iter()
        .enumerate()
        .map(|(k, &t)| {
            Record::Gps(GpsFix {
                t_us: (t * 1e6).round() as u64,
                lat_e7: Some(522_000_000 + 1000 * k as i32),
                lon_e7: Some(68_800_000),
                fix: FixMode::Fix3d,
                ..GpsFix::default()
            })
        })
        .collect();
    let extras = Extras {
        records,
        ..Extras::default()
    };
    analysis_support::write_log(path, &Ride::new(30.0, 5.0, 0.0, 0.0, 0.0), &extras);
}

/// Five seconds without any fix record still continue a segment, more
/// than that starts a new one; the document is whole, and no warning is
/// given for a track that has points.
#[test]
fn a_silence_over_five_seconds_splits_the_track() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00004.WBL");
    let times = [1.0, 2.0, 3.0, 8.0, 14.0, 15.0];
    log_with_fixes(&log, &times);
    let out = wobblog().arg("gpx").arg(&log).output().unwrap();
    assert!(out.status.success());
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let gpx = String::from_utf8(out.stdout).unwrap();
    assert!(gpx.trim_end().ends_with("</gpx>"), "{gpx}");
    let counts: Vec<usize> = segments(&gpx).iter().map(Vec::len).collect();
    assert_eq!(counts, [4, 2], "3 s to 8 s is 5 s, 8 s to 14 s is 6 s");
}

/// `--from/--to` in seconds since boot keep the fixes inside.
#[test]
fn the_window_keeps_the_fixes_inside_it() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00005.WBL");
    let times: Vec<f64> = (1..=20).map(f64::from).collect();
    log_with_fixes(&log, &times);
    let gpx = stdout_of(
        wobblog()
            .arg("gpx")
            .arg(&log)
            .args(["--from", "5", "--to", "9.5"]),
    );
    let lats: Vec<f64> = segments(&gpx).iter().flatten().map(|p| p.0).collect();
    let expected: Vec<f64> = (4..9).map(|k| 52.2 + 1e-4 * f64::from(k)).collect();
    assert_eq!(lats.len(), expected.len(), "{gpx}");
    assert!(
        lats.iter()
            .zip(&expected)
            .all(|(a, b)| (a - b).abs() < 1e-9),
        "{lats:?}"
    );
}
