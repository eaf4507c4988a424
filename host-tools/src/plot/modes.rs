//! The seed paper's Figure 8: every wobble episode as a point in the complex
//! plane, real part sigma (growth rate) against imaginary part 2 pi f, one
//! colour and shape per run. Right of the zero line the wobble grew by
//! itself. Beside it, sigma and frequency against the speed at onset: where
//! the wobble turns unstable, and whether its frequency follows the speed.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{numbers_chart, padded_range, titled_page, Figure, FONT};
use crate::analysis::{Episode, Stability};

/// Axis labels.
pub const X_LABEL: &str = "real part sigma (1/s)";
/// Axis labels.
pub const Y_LABEL: &str = "imaginary part 2 pi f (rad/s)";
/// Radius of an episode's dot, px.
pub const DOT_PX: i32 = 5;

/// Colour of censored episodes (cut by a gap or an end of the data), drawn
/// hollow whatever their run.
pub const CENSORED_COLOUR: RGBColor = RGBColor(0xa0, 0xa0, 0xa0);

/// Colour of the zero lines of sigma: the boundary between stable (left,
/// below) and unstable (right, above) wobble.
pub const ZERO_LINE_COLOUR: RGBColor = RGBColor(0x30, 0x30, 0x30);

/// An episode's value on a panel's axis.
type Coordinate = fn(&Episode) -> f64;

/// Which axis of a panel is sigma, so its zero line is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum SigmaAxis {
    X,
    Y,
    None,
}

/// One colour per run, in turn: dark enough on white to tell apart.
const RUN_COLOURS: [RGBColor; 8] = [
    RGBColor(0x1f, 0x4e, 0x9a),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0x8c, 0x56, 0x4b),
    RGBColor(0x17, 0xbe, 0xcf),
    RGBColor(0x7f, 0x7f, 0x7f),
];

/// Marker shapes, one per round of [`RUN_COLOURS`]: run `k` has colour
/// `k % 8` and shape `k / 8 % 4`, so 32 runs stay apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// A dot.
    Circle,
    /// A triangle, point up.
    Triangle,
    /// A square.
    Square,
    /// A diamond.
    Diamond,
}

const SHAPES: [Shape; 4] = [
    Shape::Circle,
    Shape::Triangle,
    Shape::Square,
    Shape::Diamond,
];

/// The colour and shape of run number `k`.
#[must_use]
pub fn run_style(k: usize) -> (RGBColor, Shape) {
    (
        RUN_COLOURS[k % RUN_COLOURS.len()],
        SHAPES[k / RUN_COLOURS.len() % SHAPES.len()],
    )
}

/// Figure 8 over any number of runs, with a second view of each episode's
/// growth rate and frequency against its speed at onset.
pub struct ModePlot {
    runs: Vec<(String, Vec<Episode>)>,
}

/// The figure's own size, px: the complex plane on the left, the two speed
/// panels in the middle, the key on the right.
const SIZE_PX: (u32, u32) = (1400, 720);
/// Width of the key, px.
const KEY_PX: u32 = 200;

/// Hands a marker of `shape` at `at` in `style` to `draw` as its own element
/// type: one per shape, as plotters' boxed elements need a `'static` backend.
macro_rules! with_marker {
    ($shape:expr, $at:expr, $style:expr, $draw:expr) => {{
        let r = DOT_PX;
        let base = EmptyElement::at($at);
        match $shape {
            Shape::Circle => $draw(base + Circle::new((0, 0), r, $style)),
            Shape::Triangle => {
                $draw(base + Polygon::new(vec![(0, -r - 1), (r + 1, r), (-r - 1, r)], $style))
            }
            Shape::Square => $draw(base + Rectangle::new([(-r, -r), (r, r)], $style)),
            Shape::Diamond => $draw(
                base + Polygon::new(
                    vec![(0, -r - 1), (r + 1, 0), (0, r + 1), (-r - 1, 0)],
                    $style,
                ),
            ),
        }
    }};
}

impl ModePlot {
    /// The figure of each run's (name, episodes).
    #[must_use]
    pub fn new(runs: Vec<(String, Vec<Episode>)>) -> Self {
        Self { runs }
    }

    fn all(&self) -> impl Iterator<Item = &Episode> {
        self.runs.iter().flat_map(|(_, e)| e)
    }

    /// The style of an episode of run `k`.
    fn style(k: usize, e: &Episode) -> (Shape, ShapeStyle) {
        let (colour, shape) = run_style(k);
        let style = match (e.censored, e.stability) {
            // Only part of it was seen: hollow and grey.
            (true, _) => CENSORED_COLOUR.stroke_width(2),
            (false, Stability::Unstable) => colour.filled(),
            (false, Stability::Stable) => colour.stroke_width(2),
        };
        (shape, style)
    }

    /// Draws every episode as (`x(e)`, `y(e)`) on `area`, with the line where
    /// sigma is zero when sigma is on an axis.
    fn panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        labels: (&str, &str),
        (x, y): (Coordinate, Coordinate),
        sigma_on: SigmaAxis,
    ) -> Result<(), String> {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        let on_x = sigma_on == SigmaAxis::X;
        let on_y = sigma_on == SigmaAxis::Y;
        // The zero line is always in view, even when every episode is on
        // one side of it.
        let xs = self.all().map(x).chain(on_x.then_some(0.0));
        let ys = self.all().map(y).chain(on_y.then_some(0.0));
        let x_range = padded_range(xs, if on_x { 2.0 } else { 1.0 });
        let y_span = match sigma_on {
            SigmaAxis::X => 10.0,
            SigmaAxis::Y => 2.0,
            SigmaAxis::None => 1.0,
        };
        let y_range = padded_range(ys, y_span);
        let mut chart = numbers_chart(area, (12, 0), (x_range.clone(), y_range.clone()), labels)?;
        let zero_line = match sigma_on {
            SigmaAxis::X => Some(vec![(0.0, y_range.start), (0.0, y_range.end)]),
            SigmaAxis::Y => Some(vec![(x_range.start, 0.0), (x_range.end, 0.0)]),
            SigmaAxis::None => None,
        };
        if let Some(line) = zero_line {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    line,
                    ZERO_LINE_COLOUR.stroke_width(1),
                )))
                .map_err(err)?;
        }
        for (k, (_, episodes)) in self.runs.iter().enumerate() {
            for e in episodes {
                let (shape, style) = Self::style(k, e);
                with_marker!(shape, (x(e), y(e)), style, |m| chart
                    .draw_series(std::iter::once(m))
                    .map(drop)
                    .map_err(err))?;
            }
        }
        Ok(())
    }

    /// The key, outside the axes: how to read a marker, then one line per
    /// run that has episodes.
    fn key<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        let text = |s: &str, at: (i32, i32)| Text::new(s.to_string(), at, (FONT, 14));
        let mut y = 40;
        for line in ["filled: unstable", "open: stable", "grey: cut by a gap"] {
            area.draw(&text(line, (10, y))).map_err(err)?;
            y += 20;
        }
        y += 12;
        for (k, (name, episodes)) in self.runs.iter().enumerate() {
            if episodes.is_empty() {
                continue;
            }
            let (colour, shape) = run_style(k);
            with_marker!(shape, (18, y + 7), colour.filled(), |m| area
                .draw(&m)
                .map_err(err))?;
            area.draw(&text(name, (34, y))).map_err(err)?;
            y += 20;
        }
        Ok(())
    }
}

impl Figure for ModePlot {
    fn size_px(&self) -> (u32, u32) {
        SIZE_PX
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let root = titled_page(root, "Wobble modes")?;
        let (w, h) = root.dim_in_pixel();
        let (plots, key) = root.split_horizontally(w.saturating_sub(KEY_PX));
        let (plane, by_speed) = plots.split_horizontally(w.saturating_sub(KEY_PX) * 11 / 20);
        let (sigma, freq) = by_speed.split_vertically(h / 2);
        self.panel(
            &plane,
            (X_LABEL, Y_LABEL),
            (|e| e.sigma_per_s, Episode::omega_rad_s),
            SigmaAxis::X,
        )?;
        self.panel(
            &sigma,
            (SPEED_LABEL, "sigma (1/s)"),
            (|e| e.speed_at_onset_mps, |e| e.sigma_per_s),
            SigmaAxis::Y,
        )?;
        self.panel(
            &freq,
            (SPEED_LABEL, "frequency (Hz)"),
            (|e| e.speed_at_onset_mps, |e| e.freq_hz),
            SigmaAxis::None,
        )?;
        self.key(&key)
    }
}

/// The speed panels' x label.
pub const SPEED_LABEL: &str = "speed at onset (m/s)";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thirty_two_runs_have_distinct_styles() {
        let styles: Vec<(RGBColor, Shape)> = (0..32).map(run_style).collect();
        for (i, a) in styles.iter().enumerate() {
            assert!(styles[i + 1..].iter().all(|b| b != a), "run {i}");
        }
    }
}
