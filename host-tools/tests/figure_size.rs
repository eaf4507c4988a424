//! Figures for a paper: `--size` and `--dpi` set the layout and the PNG's
//! resolution, PNG lines are anti-aliased, and every key stands beside the
//! data rather than over it.

mod analysis_support;

use std::path::{Path, PathBuf};

use analysis_support::wobblog;
use wobblog::plot::timeplot::LINE_COLOUR;

const BENCHMARK: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/bicycle-model/params/benchmark.toml"
);
const PAPER: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/bicycle-model/params/paper-test-bicycle.toml"
);

/// A synthetic ride with alerts, markers and a wobble episode.
fn ride(dir: &Path) -> PathBuf {
    let log = dir.join("RUN00003.WBL");
    analysis_support::standard_log(&log);
    log
}

/// Runs wobblog with `args` and expects success.
fn draw(args: &[&str]) {
    wobblog().args(args).assert().success();
}

/// `wobblog plot LOG -o OUT EXTRA...`: its exit code and standard error.
fn plot(log: &Path, out: &Path, extra: &[&str]) -> (Option<i32>, String) {
    let done = wobblog()
        .arg("plot")
        .arg(log)
        .arg("-o")
        .arg(out)
        .args(extra)
        .output()
        .unwrap();
    (
        done.status.code(),
        String::from_utf8_lossy(&done.stderr).into_owned(),
    )
}

/// A PNG's width and height, and its pixels as RGB.
fn png_pixels(path: &Path) -> ((u32, u32), Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    buf.truncate(info.buffer_size());
    ((info.width, info.height), buf)
}

/// The `width` and `height` attributes of an SVG's root element.
fn svg_size(svg: &str) -> (String, String) {
    let root = &svg[svg.find("<svg").unwrap()..];
    let root = &root[..root.find('>').unwrap()];
    let attr = |name: &str| {
        let at = root.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
        root[at..at + root[at..].find('"').unwrap()].to_string()
    };
    (attr("width"), attr("height"))
}

/// Every `<text>` element of `svg`: its `x` and its text.
fn texts_at(svg: &str) -> Vec<(f64, String)> {
    svg.split("<text")
        .skip(1)
        .filter_map(|e| {
            let x = e.split_once(" x=\"")?.1.split('"').next()?.parse().ok()?;
            let text = e[e.find('>')? + 1..e.find("</text>")?].trim().to_string();
            Some((x, text))
        })
        .collect()
}

/// The largest x of every polyline of `svg` stroked in `colour` (`#RRGGBB`).
fn rightmost_point(svg: &str, colour: &str) -> f64 {
    svg.split("<polyline")
        .skip(1)
        .filter(|e| e[..e.find('>').unwrap()].contains(&format!("stroke=\"{colour}\"")))
        .flat_map(|e| {
            let points = e.split_once("points=\"").unwrap().1;
            let points = &points[..points.find('"').unwrap()];
            points
                .split_whitespace()
                .map(|p| p.split(',').next().unwrap().parse::<f64>().unwrap())
                .collect::<Vec<_>>()
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

#[test]
fn size_and_dpi_set_the_image() {
    let dir = tempfile::tempdir().unwrap();
    let log = ride(dir.path());
    let log = log.to_str().unwrap();
    let out = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    // 7 x 5 in at 300 dpi; the layout in pixels at the default 96 dpi.
    let print = out("print.png");
    draw(&["plot", log, "-o", &print, "--size", "7x5in", "--dpi", "300"]);
    assert_eq!(png_pixels(Path::new(&print)).0, (2100, 1500));
    let screen = out("screen.png");
    draw(&["plot", log, "-o", &screen, "--size", "800x600"]);
    assert_eq!(png_pixels(Path::new(&screen)).0, (800, 600));
    // The same layout at 192 dpi: twice the pixels each way.
    let sharp = out("sharp.png");
    draw(&[
        "plot", log, "-o", &sharp, "--size", "800x600", "--dpi", "192",
    ]);
    assert_eq!(png_pixels(Path::new(&sharp)).0, (1600, 1200));
    // An SVG is laid out at the size, in CSS pixels: 17 x 12 cm.
    let svg = out("paper.svg");
    draw(&["plot", log, "-o", &svg, "--size", "17x12cm", "--dpi", "600"]);
    let (w, h) = svg_size(&std::fs::read_to_string(&svg).unwrap());
    assert_eq!((w.as_str(), h.as_str()), ("643", "454"));
    // Without them, each figure's own size.
    let own = out("own.png");
    draw(&["model", "plot", BENCHMARK, "-o", &own]);
    assert_eq!(png_pixels(Path::new(&own)).0, (1200, 900));
    let mm = out("mm.png");
    draw(&[
        "model",
        "plot",
        BENCHMARK,
        "-o",
        &mm,
        "--size",
        "254x127mm",
        "--dpi",
        "48",
    ]);
    assert_eq!(png_pixels(Path::new(&mm)).0, (480, 240));
}

#[test]
fn every_figure_is_drawn_at_the_smallest_size() {
    let dir = tempfile::tempdir().unwrap();
    let log = ride(dir.path());
    let log = log.to_str().unwrap();
    for (k, args) in [
        vec!["plot", log],
        vec!["wobble", log, "--plot"],
        vec!["model", "plot", PAPER, "--both"],
        vec!["model", "compare", BENCHMARK, log],
        vec![
            "model",
            "sweep",
            BENCHMARK,
            "--param",
            "geometry.trail",
            "--factors",
            "1,2",
        ],
    ]
    .into_iter()
    .enumerate()
    {
        let png = dir.path().join(format!("small{k}.png"));
        let png = png.to_str().unwrap();
        let mut args = args;
        if args.last() != Some(&"--plot") {
            args.push("-o");
        }
        args.extend([png, "--size", "480x320"]);
        wobblog().args(&args).assert().success();
        assert_eq!(png_pixels(Path::new(png)).0, (480, 320), "{args:?}");
    }
}

#[test]
fn bad_sizes_are_usage_errors_that_say_what_to_give() {
    let dir = tempfile::tempdir().unwrap();
    let log = ride(dir.path());
    let png = dir.path().join("x.png");
    for (size, says) in [
        ("100x100", "at least 480x320 px"),
        ("3x2in", "at least 480x320 px"),
        ("7x", "is not a number"),
        ("7by5", "no `x`"),
        ("100000x100000", "larger than any figure needs"),
    ] {
        let (code, err) = plot(&log, &png, &["--size", size]);
        assert_eq!(code, Some(2), "--size {size}: {err}");
        assert!(err.contains(says), "--size {size}: {err}");
    }
    for dpi in ["0", "-96", "5000", "many"] {
        let (code, err) = plot(&log, &png, &[&format!("--dpi={dpi}")]);
        assert_eq!(code, Some(2), "--dpi {dpi}: {err}");
        assert!(err.contains("24 to 2400"), "--dpi {dpi}: {err}");
    }
    // Each sane alone, together too many pixels: refused, nothing written.
    let (code, err) = plot(&log, &png, &["--size", "10000x10000", "--dpi", "1200"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("lower --dpi or --size"), "{err}");
    assert!(!png.exists());
}

/// Anti-aliased lines leave pixels part way between the line's colour and
/// the white beside it; an aliased drawing has only the colours it drew
/// (shaded spans and text are in other colours).
#[test]
fn png_lines_are_anti_aliased() {
    let dir = tempfile::tempdir().unwrap();
    let log = ride(dir.path());
    let png = dir.path().join("fig6.png");
    assert_eq!(plot(&log, &png, &[]).0, Some(0));
    let (_, pixels) = png_pixels(&png);
    let line = [LINE_COLOUR.0, LINE_COLOUR.1, LINE_COLOUR.2].map(f64::from);
    let partial = pixels
        .chunks_exact(3)
        .filter(|p| {
            // The share of the line in this pixel, from its red channel,
            // must explain the other two channels as well.
            let t = (255.0 - f64::from(p[0])) / (255.0 - line[0]);
            (0.2..0.8).contains(&t)
                && (0..3).all(|c| {
                    let blend = 255.0 + t * (line[c] - 255.0);
                    (f64::from(p[c]) - blend).abs() < 8.0
                })
        })
        .count();
    assert!(partial > 1000, "{partial} partly covered line pixels");
}

/// The key's entries lie right of every data point, on Figure 6 and on the
/// eigenvalue figure with its eleven entries.
#[test]
fn keys_stand_beside_the_data() {
    let dir = tempfile::tempdir().unwrap();
    let log = ride(dir.path());
    let fig6 = dir.path().join("fig6.svg");
    assert_eq!(plot(&log, &fig6, &[]).0, Some(0));
    let svg = std::fs::read_to_string(&fig6).unwrap();
    let line = format!(
        "#{:02X}{:02X}{:02X}",
        LINE_COLOUR.0, LINE_COLOUR.1, LINE_COLOUR.2
    );
    let right = rightmost_point(&svg, &line);
    assert!(right > 900.0, "{right}");
    let texts = texts_at(&svg);
    for label in [
        "wobble alert (on board)",
        "rider marker",
        "wobble episode (host)",
    ] {
        let (x, _) = texts.iter().find(|t| t.1 == label).expect(label);
        assert!(*x > right, "{label} at x {x}, data to {right}");
    }
    let fig4 = dir.path().join("fig4.svg");
    wobblog()
        .args(["model", "plot", PAPER, "--both", "-o"])
        .arg(&fig4)
        .assert()
        .success();
    let svg = std::fs::read_to_string(&fig4).unwrap();
    // The wobble's colour: its lines run to the fastest speed.
    let right = rightmost_point(&svg, "#D62728");
    let texts = texts_at(&svg);
    let keyed: Vec<&(f64, String)> = texts.iter().filter(|t| t.1.contains(": ")).collect();
    assert_eq!(keyed.len(), 11, "{keyed:?}");
    for (x, label) in keyed {
        assert!(*x > right, "{label} at x {x}, data to {right}");
        assert!(!label.contains("(("), "{label}");
    }
}
