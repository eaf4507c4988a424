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
/// Fixes further apart in time than this are not joined, s (nor the
/// points drawn on either side of them when the line is thinned).
const GAP_S: f64 = 5.0;
/// Points of the line at most: every fix, every second one, every fourth...
/// whichever fits; an hour of 20 Hz fixes is thinned to one in 32 (some
/// metres apart at riding speed, about a pixel of the drawing of a long
/// route).
const MAX_POINTS: usize = 4000;

/// The SVG of `fixes` (in time order), with a dot at each of `onsets_s`
/// (the first fix not before it, else the last); `None` without a fix.
#[must_use]
pub fn track_svg(fixes: &[Fix], onsets_s: &[f64]) -> Option<String> {
    let mut track = TrackBuilder::new(onsets_s);
    for &fix in fixes {
        track.push(fix);
    }
    track.finish()
}

/// A fix on the drawing's flat projection: time, metres east and north of
/// the first fix.
type Point = (f64, f64, f64);

/// Builds the track's drawing fix by fix, holding at most [`MAX_POINTS`]
/// of them: every `stride`-th fix is kept, and the stride doubles (every
/// other kept point dropped) whenever more would be kept.
pub struct TrackBuilder {
    /// Latitude and longitude of the first fix, and the cosine of its
    /// latitude.
    origin: Option<(f64, f64, f64)>,
    /// The box around every fix, m: west, east, south, north.
    bounds: (f64, f64, f64, f64),
    /// Fixes taken.
    fixes: usize,
    stride: usize,
    /// Every `stride`-th fix, and whether the line breaks before it (a
    /// gap between two fixes since the point kept before).
    kept: Vec<(Point, bool)>,
    /// A gap since the last point kept.
    gap: bool,
    first: Option<Point>,
    last: Option<Point>,
    /// The onsets in time order with their place in the list given, and
    /// the fix found for each.
    onsets: Vec<(f64, usize)>,
    found: Vec<Option<Point>>,
    /// Onsets (in time order) that have their fix.
    placed: usize,
}

impl TrackBuilder {
    /// A track with a dot at each of `onsets_s`.
    #[must_use]
    pub fn new(onsets_s: &[f64]) -> Self {
        let mut onsets: Vec<(f64, usize)> = onsets_s.iter().copied().zip(0..).collect();
        onsets.sort_by(|a, b| a.0.total_cmp(&b.0));
        Self {
            origin: None,
            bounds: (f64::MAX, f64::MIN, f64::MAX, f64::MIN),
            fixes: 0,
            stride: 1,
            kept: Vec::new(),
            gap: false,
            first: None,
            last: None,
            found: vec![None; onsets.len()],
            onsets,
            placed: 0,
        }
    }

    /// Takes the next fix, in time order.
    pub fn push(&mut self, (t, lat, lon): Fix) {
        let (lat0, lon0, coslat) = *self
            .origin
            .get_or_insert_with(|| (lat, lon, lat.to_radians().cos().max(1e-6)));
        let p = (
            t,
            (lon - lon0) * M_PER_DEG * coslat,
            (lat - lat0) * M_PER_DEG,
        );
        let b = &mut self.bounds;
        *b = (b.0.min(p.1), b.1.max(p.1), b.2.min(p.2), b.3.max(p.2));
        while let Some(&(onset, at)) = self.onsets.get(self.placed) {
            if p.0 < onset {
                break;
            }
            self.found[at] = Some(p);
            self.placed += 1;
        }
        if self.last.is_some_and(|l| p.0 - l.0 > GAP_S) {
            self.gap = true;
        }
        if self.fixes.is_multiple_of(self.stride) {
            if self.kept.len() == MAX_POINTS {
                self.thin();
            }
            if self.fixes.is_multiple_of(self.stride) {
                self.kept.push((p, std::mem::take(&mut self.gap)));
            }
        }
        self.first.get_or_insert(p);
        self.last = Some(p);
        self.fixes += 1;
    }

    /// Doubles the stride: every other point kept is dropped, a gap before
    /// it passed on to the next.
    fn thin(&mut self) {
        self.stride *= 2;
        let (mut i, mut carry) = (0, false);
        self.kept.retain_mut(|(_, gap)| {
            let keep = i % 2 == 0;
            i += 1;
            if keep {
                *gap |= std::mem::take(&mut carry);
            } else {
                carry = *gap;
            }
            keep
        });
        self.gap |= carry;
    }

    /// The drawing; `None` without a fix.
    #[must_use]
    pub fn finish(self) -> Option<String> {
        let (first, last) = (self.first?, self.last?);
        let (x0, x1, y0, y1) = self.bounds;
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
        // The last fix is drawn whether or not the stride falls on it.
        let last_index = self.fixes - 1;
        let end = (!last_index.is_multiple_of(self.stride)).then_some((last, self.gap));
        for &((_, x, y), gap) in self.kept.iter().chain(&end) {
            if gap {
                flush_line(&mut svg, &mut line);
            }
            let (a, b) = px(x, y);
            let _ = write!(line, "{a:.1},{b:.1} ");
        }
        flush_line(&mut svg, &mut line);
        let dot = |svg: &mut String, &(_, x, y): &Point, colour: &str, title: &str| {
            let (a, b) = px(x, y);
            let _ = write!(
                svg,
                r##"<circle cx="{a:.1}" cy="{b:.1}" r="5" fill="{colour}"><title>{title}</title></circle>"##
            );
        };
        let mut onsets = self.onsets;
        onsets.sort_by_key(|o| o.1);
        for ((onset, _), found) in onsets.iter().zip(&self.found) {
            dot(
                &mut svg,
                &found.unwrap_or(last),
                "#d62728",
                &format!("wobble at {onset:.1} s"),
            );
        }
        dot(&mut svg, &first, "#2ca02c", "start");
        dot(&mut svg, &last, "#222", "end");
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
    fn the_builder_holds_at_most_its_points_whatever_the_track() {
        let mut track = TrackBuilder::new(&[10.0, 60_000.0]);
        for i in 0..1_000_000 {
            let t = f64::from(i) * 0.05;
            track.push((t, 52.0 + t * 1e-6, 6.0));
            assert!(track.kept.len() <= MAX_POINTS);
        }
        // The wobble's dot is at the first fix at or after it, the one
        // past the end at the last fix.
        assert_eq!(track.found[0].map(|p| p.0), Some(10.0));
        assert_eq!(track.found[1], None);
        assert!(track.kept.len() > MAX_POINTS / 2);
        assert!(track.finish().unwrap().contains("wobble at 60000.0 s"));
    }

    #[test]
    fn a_thinned_track_breaks_at_its_gaps_only() {
        // 10 Hz fixes for 5.5 h, thinned to points 6.4 s apart, one 60 s
        // gap in the middle.
        let fixes: Vec<Fix> = (0..200_000)
            .map(|i| {
                let t = f64::from(i) * 0.1 + if i >= 100_000 { 60.0 } else { 0.0 };
                (t, 52.0 + t * 1e-6, 6.0 + (t / 1000.0).sin() * 1e-3)
            })
            .collect();
        let svg = track_svg(&fixes, &[]).unwrap();
        assert_eq!(svg.matches("<polyline").count(), 2);
    }

    #[test]
    fn no_fix_no_drawing_and_gaps_split_the_line() {
        assert!(track_svg(&[], &[]).is_none());
        let fixes = [(0.0, 52.0, 6.0), (1.0, 52.0001, 6.0), (20.0, 52.0002, 6.0)];
        let svg = track_svg(&fixes, &[]).unwrap();
        assert_eq!(svg.matches("<polyline").count(), 2);
    }
}
