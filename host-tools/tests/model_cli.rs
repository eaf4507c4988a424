//! `wobblog model`: the eigenvalue CSV interface, critical speeds kept out
//! of it, and errors naming the file and the parameter.

use assert_cmd::Command;
use std::path::{Path, PathBuf};

fn wobblog() -> Command {
    Command::cargo_bin("wobblog").unwrap()
}

/// `wobblog model SUB` on a shipped parameter file.
fn model(sub: &str, file: &str) -> Command {
    let mut cmd = wobblog();
    cmd.args(["model", sub]).arg(params(file));
    cmd
}

/// Encodes a ride CSV into a card log.
fn encode(csv: &Path, log: &Path) {
    wobblog()
        .args(["encode", "--csv"])
        .arg(csv)
        .arg("-o")
        .arg(log)
        .assert()
        .success();
}

fn params(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("bicycle-model/params")
        .join(name)
}

#[test]
fn eig_csv_has_one_row_per_eigenvalue_and_critical_speeds_on_stderr() {
    let out = model("eig", "benchmark.toml")
        .args(["--speeds", "0:10:0.5", "--format", "csv"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("speed_mps,mode,re_per_s,im_rad_per_s"));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 21 * 4, "4 eigenvalues at each of 21 speeds");
    assert!(rows.iter().all(|r| r.len() == 4));
    let at5: Vec<&Vec<&str>> = rows.iter().filter(|r| r[0] == "5").collect();
    let weave: Vec<f64> = at5
        .iter()
        .filter(|r| r[1] == "weave")
        .map(|r| r[3].parse().unwrap())
        .collect();
    assert_eq!(weave.len(), 2, "both members of the weave pair");
    assert!(
        (weave[0] + 4.46486771378823).abs() < 1e-10 && (weave[1] - 4.46486771378823).abs() < 1e-10
    );
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(stderr.contains("weave speed 4.292382536 m/s"), "{stderr}");
    assert!(stderr.contains("capsize speed 6.024262015 m/s"), "{stderr}");
}

#[test]
fn eig_writes_its_output_file_whole() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("eig.jsonl");
    model("eig", "benchmark.toml")
        .args(["--speeds", "4:7:0.25", "--format", "jsonl", "-o"])
        .arg(&target)
        .assert()
        .success();
    let text = std::fs::read_to_string(&target).unwrap();
    let last: serde_json::Value = serde_json::from_str(text.lines().last().unwrap()).unwrap();
    assert_eq!(last["mode"], "capsize");
    assert!((last["critical_speed_mps"].as_f64().unwrap() - 6.024262015).abs() < 1e-9);
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "no temporary file left"
    );
}

#[test]
fn unphysical_parameters_exit_1_naming_file_and_parameter() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.toml");
    let text = std::fs::read_to_string(params("benchmark.toml")).unwrap();
    std::fs::write(
        &bad,
        text.replacen(
            "value = 3.0, unit = \"kg\"",
            "value = -3.0, unit = \"kg\"",
            1,
        ),
    )
    .unwrap();
    let out = wobblog().args(["model", "eig"]).arg(&bad).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        stderr.contains("bad.toml: front_wheel.mass: unphysical"),
        "{stderr}"
    );
}

#[test]
fn usage_errors_exit_2() {
    let out = model("eig", "benchmark.toml")
        .args(["--speeds", "5:1:0.1"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
}

fn corpus_log(dir: &Path, name: &str) -> PathBuf {
    let csv = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../hil-tests/fixtures/corpus")
        .join(format!("{name}.csv"));
    let log = dir.join(format!("{name}.WBL"));
    encode(&csv, &log);
    log
}

/// `model sweep` of the test bicycle's front cornering stiffness at x 0.5,
/// 1 and 2, over `speeds`.
fn cornering_sweep(speeds: &str) -> Command {
    let mut cmd = model("sweep", "test-bicycle.toml");
    cmd.args([
        "--param",
        "front_tyre.cornering_stiffness",
        "--factors",
        "0.5,1,2",
        "--speeds",
        speeds,
    ]);
    cmd
}

#[test]
fn plot_and_sweep_draw_figures_and_print_critical_speeds() {
    let dir = tempfile::tempdir().unwrap();
    let fig = dir.path().join("fig4.png");
    model("plot", "test-bicycle.toml")
        .args(["--both", "--speeds", "0:8:0.25", "-o"])
        .arg(&fig)
        .assert()
        .success();
    assert!(std::fs::read(&fig).unwrap().starts_with(b"\x89PNG"));
    let out = cornering_sweep("0:8:0.25").output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(
        text.matches("front_tyre.cornering_stiffness x").count(),
        3,
        "{text}"
    );
    assert!(
        text.contains("x 1 (11.5 1/rad):\n  wobble speed 3.80"),
        "{text}"
    );
    let out = model("sweep", "test-bicycle.toml")
        .args(["--param", "front_tyre.no_such", "--speeds", "0:1:1"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8(out.stderr)
        .unwrap()
        .contains("front_tyre.no_such: no such parameter"));
}

/// Every two-point `<polyline>` of `svg` drawn level at one height, as
/// (height, stroke width, left end, right end).
fn level_segments(svg: &str) -> Vec<(i32, u32, i32, i32)> {
    let attr = |el: &str, name: &str| -> Option<String> {
        let from = el.find(&format!("{name}=\""))? + name.len() + 2;
        Some(el[from..from + el[from..].find('"')?].to_string())
    };
    svg.split("<polyline")
        .skip(1)
        .filter_map(|el| {
            let width = attr(el, "stroke-width")?.parse().ok()?;
            let points: Vec<(i32, i32)> = attr(el, "points")?
                .split_whitespace()
                .map(|p| {
                    let (x, y) = p.split_once(',').unwrap();
                    (x.parse().unwrap(), y.parse().unwrap())
                })
                .collect();
            match points[..] {
                [(x0, y0), (x1, y1)] if y0 == y1 => Some((y0, width, x0, x1)),
                _ => None,
            }
        })
        .collect()
}

#[test]
fn sweep_key_draws_each_factors_swatch_as_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let fig = dir.path().join("fig7.svg");
    cornering_sweep("0:8:0.5")
        .arg("-o")
        .arg(&fig)
        .assert()
        .success();
    let svg = std::fs::read_to_string(&fig).unwrap();
    // The key's frame is the last rectangle before its first entry; the
    // swatches are the level segments inside it.
    let first = svg.find("wobble: x 0.5").expect("the key");
    let frame_at = svg[..first].rfind("<rect").unwrap();
    let frame = &svg[frame_at..first];
    let number = |name: &str| -> i32 {
        let at = frame.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
        frame[at..at + frame[at..].find('"').unwrap()]
            .parse()
            .unwrap()
    };
    let (left, top) = (number("x"), number("y"));
    let (right, bottom) = (left + number("width"), top + number("height"));
    let mut rows: Vec<(i32, Vec<(u32, i32)>)> = Vec::new();
    for (y, width, x0, x1) in level_segments(&svg[frame_at..]) {
        if x0 < left || x1 > right || y < top || y > bottom {
            continue;
        }
        match rows.iter_mut().find(|(row, _)| *row == y) {
            Some((_, segs)) => segs.push((width, x1 - x0)),
            None => rows.push((y, vec![(width, x1 - x0)])),
        }
    }
    rows.sort_by_key(|(y, _)| *y);
    let swatches: Vec<_> = rows.into_iter().map(|(_, segs)| segs).collect();
    assert_eq!(swatches.len(), 6, "{swatches:?}");
    // Entries in the order of the factors, wobble then weave for each:
    // x 0.5 thin and solid, x 1 thick and solid, x 2 dotted.
    for pair in &swatches[0..2] {
        assert_eq!(pair, &vec![(1, 24)], "{swatches:?}");
    }
    for pair in &swatches[2..4] {
        assert_eq!(pair, &vec![(3, 24)], "{swatches:?}");
    }
    for dots in &swatches[4..6] {
        assert!(dots.len() >= 4, "{swatches:?}");
        assert!(
            dots.iter().all(|&(w, len)| w == 2 && len <= 3),
            "{swatches:?}"
        );
    }
}

#[test]
fn compare_prints_residuals_and_fit_writes_the_fitted_file() {
    let dir = tempfile::tempdir().unwrap();
    let log = corpus_log(dir.path(), "wobble_fig6");
    let out = model("compare", "test-bicycle.toml")
        .arg(&log)
        .arg("-o")
        .arg(dir.path().join("fig8.svg"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let row = text
        .lines()
        .find(|l| l.starts_with("wobble_fig6.WBL"))
        .expect(&text);
    assert_eq!(row.split_whitespace().nth(1), Some("wobble"), "{row}");
    let cols: Vec<f64> = row
        .split_whitespace()
        .skip(2)
        .take(8)
        .map(|c| c.parse().unwrap())
        .collect();
    // measured minus model, as printed
    assert!((cols[2] - cols[3] - cols[4]).abs() < 0.011, "{row}");
    assert!(text.contains("rms residuals over 1 episode:"));
    let fitted = dir.path().join("fitted.toml");
    let out = model("fit", "test-bicycle.toml")
        .arg(&log)
        .args(["--param", "steer_head.damping", "-o"])
        .arg(&fitted)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let written = wobble_model::ParamSet::load(&fitted).unwrap();
    let q = written.quantity("steer_head.damping").unwrap();
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert!(stdout.contains(&format!("steer_head.damping = {:.6}", q.value)));
    // The fitted file keeps its evidence: the value's interval (as printed)
    // and what it came from, a name of its own, and each episode's
    // residual against the fitted model.
    let ci = stdout
        .lines()
        .find(|l| l.contains("steer_head.damping ="))
        .and_then(|l| l.split("+/- ").nth(1))
        .and_then(|r| r.split_whitespace().next())
        .and_then(|v| v.parse::<f64>().ok())
        .expect(&stdout);
    assert!(
        q.source.starts_with("fitted by wobblog model fit: "),
        "{}",
        q.source
    );
    let stated: f64 = q
        .source
        .split("+/- ")
        .nth(1)
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!((stated - ci).abs() <= 1e-6, "{} vs {ci}", q.source);
    assert!(
        q.source
            .contains("(95 %), to 1 wobble episode of 1 log (wobble_fig6.WBL); rms residuals"),
        "{}",
        q.source
    );
    assert!(
        written.name.ends_with(", fitted to 1 wobble episode"),
        "{}",
        written.name
    );
    let text = std::fs::read_to_string(&fitted).unwrap();
    let residual = text
        .lines()
        .find(|l| l.starts_with("# wobble_fig6.WBL, "))
        .expect(&text);
    let cols: Vec<f64> = residual[2..]
        .split(", ")
        .skip(1)
        .map(|c| c.parse().unwrap())
        .collect();
    assert_eq!(cols.len(), 6, "{residual}");
    // With one episode its residuals are the fit's RMS residuals, as
    // printed (worked out again here from the fitted file's model).
    let rms: Vec<f64> = stdout
        .lines()
        .find(|l| l.starts_with("rms residuals: "))
        .expect(&stdout)
        .trim_start_matches("rms residuals: ")
        .split(", ")
        .map(|p| p.split_whitespace().next().unwrap().parse().unwrap())
        .collect();
    assert!(
        (cols[3].abs() - rms[0]).abs() <= 0.002,
        "{residual} vs {rms:?}"
    );
    assert!(
        (cols[5].abs() - rms[1]).abs() <= 0.002,
        "{residual} vs {rms:?}"
    );
}

#[test]
fn eig_whipple_gives_the_four_states_of_the_lumped_bicycle() {
    let out = model("eig", "test-bicycle.toml")
        .args(["--whipple", "--speeds", "5:5:1", "--format", "csv"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let modes: Vec<&str> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap())
        .collect();
    assert_eq!(modes.len(), 4, "{text}");
    assert!(
        modes.contains(&"weave") && modes.contains(&"castering"),
        "{text}"
    );
}

#[test]
fn censored_episodes_are_compared_but_never_fitted() {
    let dir = tempfile::tempdir().unwrap();
    // The Figure 6 ride cut off while its wobble still grows: the episode
    // meets the end of the data.
    let csv =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../hil-tests/fixtures/corpus/wobble_fig6.csv");
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    let mut cut = String::from(lines.next().unwrap());
    cut.push('\n');
    for line in lines.take_while(|l| l.split(',').next().unwrap().parse::<f64>().unwrap() < 14.6) {
        cut.push_str(line);
        cut.push('\n');
    }
    let cut_csv = dir.path().join("cut.csv");
    std::fs::write(&cut_csv, cut).unwrap();
    let log = dir.path().join("CUT.WBL");
    encode(&cut_csv, &log);
    let out = model("compare", "test-bicycle.toml")
        .arg(&log)
        .output()
        .unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    let row = text
        .lines()
        .find(|l| l.starts_with("CUT.WBL"))
        .expect(&text);
    assert!(row.ends_with("yes"), "{text}");
    assert!(
        text.contains("no episodes to compare") || text.contains("over 0 episodes"),
        "{text}"
    );
    let out = model("fit", "test-bicycle.toml")
        .arg(&log)
        .args(["--param", "steer_head.damping", "-o"])
        .arg(dir.path().join("fitted.toml"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8(out.stderr)
        .unwrap()
        .contains("0 episodes cannot determine 1 parameters"));
    assert!(!dir.path().join("fitted.toml").exists());
}

#[test]
fn eig_no_slip_has_the_eight_states_of_the_constrained_bicycle() {
    let out = model("eig", "test-bicycle.toml")
        .args([
            "--speeds",
            "0:8:1",
            "--format",
            "csv",
            "--contacts",
            "no-slip",
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(text.lines().count(), 1 + 9 * 8, "8 eigenvalues at 9 speeds");
    let at4: Vec<&str> = text.lines().filter(|l| l.starts_with("4,")).collect();
    assert_eq!(
        at4.iter().filter(|l| l.contains(",wobble,")).count(),
        2,
        "{text}"
    );
    assert_eq!(
        at4.iter().filter(|l| l.contains(",weave,")).count(),
        2,
        "{text}"
    );
    // The shipped file states its camber relaxation lengths: no note.
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(!stderr.contains("not given"), "{stderr}");
    // A file that leaves them out is told so, once each.
    let dir = tempfile::tempdir().unwrap();
    let shipped = std::fs::read_to_string(params("test-bicycle.toml")).unwrap();
    let without: String = shipped
        .lines()
        .filter(|l| !l.starts_with("camber_relaxation_length"))
        .map(|l| format!("{l}\n"))
        .collect();
    let file = dir.path().join("without.toml");
    std::fs::write(&file, without).unwrap();
    let out = wobblog()
        .args(["model", "eig", "--speeds", "4:4:1"])
        .arg(&file)
        .output()
        .unwrap();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(
        stderr.matches("camber_relaxation_length not given").count(),
        2,
        "{stderr}"
    );
    let both = model("eig", "benchmark.toml")
        .args(["--whipple", "--contacts", "no-slip"])
        .output()
        .unwrap();
    assert_eq!(
        both.status.code(),
        Some(2),
        "--whipple and --contacts conflict"
    );
}

/// `model plot` marks each critical speed on the real part's zero line,
/// named with its speed: on the benchmark, the published weave and capsize
/// speeds (4.292 and 6.024 m/s, Meijaard et al. 2007).
#[test]
fn plot_marks_the_critical_speeds() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("fig4.svg");
    let out = model("plot", "benchmark.toml")
        .arg("-o")
        .arg(&svg)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&svg).unwrap();
    for mark in ["weave 4.29 m/s", "capsize 6.02 m/s"] {
        assert!(text.contains(mark), "{mark}");
    }
    let marks = text
        .split("<text")
        .filter_map(|e| Some(e[e.find('>')? + 1..e.find("</text>")?].trim().to_owned()))
        .filter(|t| t.ends_with(" m/s"))
        .count();
    assert_eq!(marks, 2, "two critical speeds");
}
