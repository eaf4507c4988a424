//! The GPS track as an SVG drawing: the fixes on a local flat projection
//! (no map tiles: the page works offline), north up, with a scale bar, the
//! start and end, and where each unstable wobble began.

use std::fmt::Write;

/// A fix: time since boot, latitude and longitude, degrees.
pub type Fix = (f64, f64, f64);

/// Drawing size, px.
const SIZE: (f64, f64) = (640.0, 420.0);
const PAD: f64 = 24.0;
/// Metres per degree of latitude (mean).
const M_PER_DEG: f64 = 111_195.0;
/// Fixes further apart in time than this are not joined, s.
const GAP_S: f64 = 5.0;
/// Points of the line at most: an hour of 20 Hz fixes is thinned to one
/// in eighteen (a few metres apart at riding speed, under a pixel of the
/// drawing of a long route).
const MAX_POINTS: usize = 4000;

/// The SVG of `fixes` (in time order), with a dot at each of `onsets_s`
/// (the fix nearest in time); `None` without a fix.
#[must_use]
pub fn track_svg(fixes: &[Fix], onsets_s: &[f64]) -> Option<String> {
    let (&(_, lat0, lon0), _) = fixes.split_first()?;
    let coslat = lat0.to_radians().cos().max(1e-6);
    let metres: Vec<(f64, f64, f64)> = fixes
        .iter()
        .map(|&(t, lat, lon)| {
            (
                t,
                (lon - lon0) * M_PER_DEG * coslat,
                (lat - lat0) * M_PER_DEG,
            )
        })
        .collect();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(_, x, y) in &metres {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    // A track of one point or a straight line still gets a 20 m box.
    let span = (x1 - x0).max(y1 - y0).max(20.0);
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let scale = ((SIZE.0 - 2.0 * PAD).min(SIZE.1 - 2.0 * PAD)) / span;
    let px = |x: f64, y: f64| {
        (
            0.5 * SIZE.0 + (x - cx) * scale,
            0.5 * SIZE.1 - (y - cy) * scale,
        )
    };
    let mut svg = String::new();
    let _ = write!(
        svg,
        r##"<svg xmlns="http://www.w3.org/2000/svg" class="track" viewBox="0 0 {w} {h}" width="{w}" height="{h}" role="img" aria-label="GPS track">"##,
        w = SIZE.0,
        h = SIZE.1
    );
    let _ = write!(
        svg,
        r##"<rect width="100%" height="100%" fill="#fafafa"/>"##
    );
    let mut line = String::new();
    let mut last_t: Option<f64> = None;
    let step = metres.len().div_ceil(MAX_POINTS).max(1);
    let last = metres.len() - 1;
    let drawn = metres
        .iter()
        .enumerate()
        .filter(|(i, _)| i % step == 0 || *i == last)
        .map(|(_, p)| p);
    for &(t, x, y) in drawn {
        if last_t.is_some_and(|l| t - l > GAP_S) {
            flush_line(&mut svg, &mut line);
        }
        last_t = Some(t);
        let (a, b) = px(x, y);
        let _ = write!(line, "{a:.1},{b:.1} ");
    }
    flush_line(&mut svg, &mut line);
    let dot = |svg: &mut String, &(_, x, y): &(f64, f64, f64), colour: &str, title: &str| {
        let (a, b) = px(x, y);
        let _ = write!(
            svg,
            r##"<circle cx="{a:.1}" cy="{b:.1}" r="5" fill="{colour}"><title>{title}</title></circle>"##
        );
    };
    for &onset in onsets_s {
        let i = metres
            .partition_point(|p| p.0 < onset)
            .min(metres.len() - 1);
        dot(
            &mut svg,
            &metres[i],
            "#d62728",
            &format!("wobble at {onset:.1} s"),
        );
    }
    dot(&mut svg, &metres[0], "#2ca02c", "start");
    dot(&mut svg, &metres[metres.len() - 1], "#222", "end");
    // A scale bar of a round length near a fifth of the drawing.
    let target = span / 5.0;
    let bar_m = [1.0, 2.0, 5.0]
        .iter()
        .flat_map(|m| (0..7).map(move |e| m * 10f64.powi(e)))
        .filter(|&m| m <= target)
        .fold(1.0, f64::max);
    let bar_px = bar_m * scale;
    let _ = write!(
        svg,
        r##"<path d="M{PAD} {y} h{bar_px:.1}" stroke="#222" stroke-width="3"/><text x="{PAD}" y="{ty}" font-size="13">{bar_m} m</text><text x="{nx}" y="{PAD}" font-size="13">N ↑</text></svg>"##,
        y = SIZE.1 - PAD,
        ty = SIZE.1 - PAD - 6.0,
        nx = SIZE.0 - PAD - 24.0,
    );
    Some(svg)
}

fn flush_line(svg: &mut String, line: &mut String) {
    if !line.is_empty() {
        let _ = write!(
            svg,
            r##"<polyline points="{}" fill="none" stroke="#1f4e9a" stroke-width="2"/>"##,
            line.trim_end()
        );
        line.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_track_north_is_drawn_upwards_with_its_wobble() {
        let fixes: Vec<Fix> = (0..100)
            .map(|i| (f64::from(i), 52.0 + f64::from(i) * 1e-5, 6.0))
            .collect();
        let svg = track_svg(&fixes, &[50.0]).unwrap();
        assert_eq!(svg.matches("<polyline").count(), 1);
        assert!(svg.contains("wobble at 50.0 s"));
        let points: Vec<f64> = svg
            .split("points=\"")
            .nth(1)
            .unwrap()
            .split('"')
            .next()
            .unwrap()
            .split([' ', ','])
            .map(|v| v.parse().unwrap())
            .collect();
        // y of the last point above (smaller than) the first's.
        assert!(points[points.len() - 1] < points[1]);
    }

    #[test]
    fn a_long_track_is_thinned_to_its_limit_with_its_end() {
        let fixes: Vec<Fix> = (0..100_000)
            .map(|i| (f64::from(i) * 0.05, 52.0 + f64::from(i) * 1e-7, 6.0))
            .collect();
        let svg = track_svg(&fixes, &[]).unwrap();
        let points = svg
            .split("points=\"")
            .nth(1)
            .unwrap()
            .split('"')
            .next()
            .unwrap();
        let n = points.split(' ').count();
        assert!((MAX_POINTS / 2..=MAX_POINTS + 1).contains(&n), "{n} points");
    }

    #[test]
    fn no_fix_no_drawing_and_gaps_split_the_line() {
        assert!(track_svg(&[], &[]).is_none());
        let fixes = [(0.0, 52.0, 6.0), (1.0, 52.0001, 6.0), (20.0, 52.0002, 6.0)];
        let svg = track_svg(&fixes, &[]).unwrap();
        assert_eq!(svg.matches("<polyline").count(), 2);
    }
}
