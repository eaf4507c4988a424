//! Figures as PNG or SVG files: the seed paper's Figure 6 (time plots of a
//! run) and Figure 8 (wobble modes in the complex plane).
//!
//! Text is drawn with the DejaVu Sans font compiled into the program, so
//! plotting needs no system font libraries; an SVG carries the font with it.

pub mod margin;
pub mod modes;
mod svg_font;
pub mod timeplot;

use std::io::Write;
use std::ops::Range;
use std::path::Path;
use std::sync::Once;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::output::Output;
use crate::CliError;

/// The font every figure uses: its family name, which an SVG's text
/// elements name and its embedded font face defines.
pub const FONT: &str = "DejaVu Sans";
static FONT_BYTES: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// A figure that can draw itself on any plotters backend.
pub trait Figure {
    /// Pixel size of the figure.
    fn size_px(&self) -> (u32, u32);
    /// Draws the figure on `root`.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String>;
}

/// Image file types, chosen by the output file's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageKind {
    /// `.png`
    Png,
    /// `.svg`
    Svg,
}

impl ImageKind {
    /// The kind for `path`, or a usage error naming the accepted extensions.
    pub fn of(path: &Path) -> Result<Self, CliError> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("png") => Ok(Self::Png),
            Some("svg") => Ok(Self::Svg),
            _ => Err(CliError::Usage(format!(
                "{}: plot files must end in .png or .svg",
                crate::text::shown(path)
            ))),
        }
    }
}

/// Draws `figure` into `out`, PNG or SVG by the output's extension, and
/// commits it. The image is drawn in memory (plotters' own file writing
/// would bypass the atomic output and report errors as debug text).
pub fn render(figure: &impl Figure, mut out: Output) -> Result<(), CliError> {
    let kind = ImageKind::of(out.name())?;
    register_font();
    let bytes = draw(figure, kind)
        .map_err(|e| CliError::file(out.name(), format!("cannot draw the plot: {e}")))?;
    out.write_all(&bytes).map_err(|e| out.error(e))?;
    out.commit()
}

fn draw(figure: &impl Figure, kind: ImageKind) -> Result<Vec<u8>, String> {
    let size = figure.size_px();
    match kind {
        ImageKind::Png => {
            let (w, h) = size;
            let mut pixels = vec![0u8; w as usize * h as usize * 3];
            {
                let root = BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area();
                figure.draw(&root)?;
                root.present().map_err(|e| e.to_string())?;
            }
            encode_png(&pixels, size).map_err(|e| e.to_string())
        }
        ImageKind::Svg => {
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
                figure.draw(&root)?;
                root.present().map_err(|e| e.to_string())?;
            }
            Ok(svg_font::embed(&svg, FONT, FONT_BYTES)?.into_bytes())
        }
    }
}

/// `figure` as SVG text to place inside a page, without the embedded font
/// (the page names the font and the browser supplies one): a report holds
/// several figures and would otherwise carry the font once per figure.
///
/// # Errors
/// The backend's error, as text.
pub fn svg_inline(figure: &impl Figure) -> Result<String, String> {
    register_font();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, figure.size_px()).into_drawing_area();
        figure.draw(&root)?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(svg)
}

/// 8-bit RGB pixels, row by row, as a PNG file.
pub fn encode_png(pixels: &[u8], (w, h): (u32, u32)) -> Result<Vec<u8>, png::EncodingError> {
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, w, h);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(pixels)?;
    writer.finish()?;
    Ok(bytes)
}

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bytes are the committed font file; if they ever failed to
        // parse, text would be missing and plotters would report it. Text
        // left in plotters' default family gets the same glyphs in a PNG
        // (and fails the SVG tests, which want the embedded family).
        for family in [FONT, "sans-serif"] {
            let _ = plotters::style::register_font(family, FontStyle::Normal, FONT_BYTES);
        }
    });
}

/// A line drawn at the figure's resolution, built in one pass over the
/// points: the lowest and the highest point of each column of a fixed grid,
/// so memory and file size depend on the figure's width, never on how many
/// points there are.
pub struct Decimator {
    origin_s: f64,
    column_s: f64,
    low: Vec<Option<(f64, f64)>>,
    high: Vec<Option<(f64, f64)>>,
    /// Whether the line runs on from this column to the next one drawn.
    joined: Vec<bool>,
    /// Column of the last point taken.
    last: Option<usize>,
}

impl Decimator {
    /// A line over `window_s` in `columns` columns (at least one).
    #[must_use]
    pub fn new(window_s: &std::ops::Range<f64>, columns: usize) -> Self {
        let columns = columns.max(1);
        Self {
            origin_s: window_s.start,
            column_s: (window_s.end - window_s.start) / columns as f64,
            low: vec![None; columns],
            high: vec![None; columns],
            joined: vec![false; columns],
            last: None,
        }
    }

    /// Takes the point `(t_s, y)`; `joins` says the line runs to it from
    /// the point before (no gap between them). Points outside the window
    /// go to its first or last column.
    pub fn push(&mut self, t_s: f64, y: f64, joins: bool) {
        let n = self.low.len();
        let at = ((t_s - self.origin_s) / self.column_s).floor();
        // A NaN column (an empty window) is column 0.
        let column = if at >= 0.0 {
            (at as usize).min(n - 1)
        } else {
            0
        };
        if let Some(prev) = self.last.filter(|&p| joins && p < column) {
            self.joined[prev] = true;
        }
        self.last = Some(column);
        let point = (t_s, y);
        if self.low[column].is_none_or(|lo| y < lo.1) {
            self.low[column] = Some(point);
        }
        if self.high[column].is_none_or(|hi| y > hi.1) {
            self.high[column] = Some(point);
        }
    }

    /// The lines: one per stretch without a gap, with each column's lowest
    /// and highest point in time order.
    #[must_use]
    pub fn lines(&self) -> Vec<Vec<(f64, f64)>> {
        let mut lines = Vec::new();
        let mut line = Vec::new();
        for ((lo, hi), &joined) in self.low.iter().zip(&self.high).zip(&self.joined) {
            let (Some(lo), Some(hi)) = (*lo, *hi) else {
                continue;
            };
            if lo == hi {
                line.push(lo);
            } else if lo.0 <= hi.0 {
                line.extend([lo, hi]);
            } else {
                line.extend([hi, lo]);
            }
            if !joined {
                lines.push(std::mem::take(&mut line));
            }
        }
        if !line.is_empty() {
            lines.push(line);
        }
        lines
    }
}

/// `root` filled white under `title`: the page every figure is drawn on.
///
/// # Errors
/// The backend's error, as text.
pub fn titled_page<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
) -> Result<DrawingArea<DB, Shift>, String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    root.titled(title, (FONT, 20)).map_err(|e| e.to_string())
}

/// A chart of `x_range` by `y_range` on `area`, `margin_px` from its edge,
/// with its mesh drawn: `x_desc` and `y_desc` as the axes' names and
/// [`tick_label`] ticks. The axes of the margin and mode figures.
///
/// # Errors
/// The backend's error, as text.
pub fn numbers_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    margin_px: u32,
    (x_range, y_range): (Range<f64>, Range<f64>),
    (x_desc, y_desc): (&str, &str),
) -> Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>, String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let mut chart = ChartBuilder::on(area)
        .margin(margin_px)
        .x_label_area_size(44)
        .y_label_area_size(64)
        .build_cartesian_2d(x_range, y_range)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_label_formatter(&|v| tick_label(*v))
        .y_label_formatter(&|v| tick_label(*v))
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 15))
        .draw()
        .map_err(err)?;
    Ok(chart)
}

/// An axis tick: the shortest of up to three decimals that shows the
/// value, and never `-0` (a tick at zero that rounding left negative).
#[must_use]
pub fn tick_label(v: f64) -> String {
    let text = format!("{v:.3}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    match text {
        "-0" | "" => "0".to_string(),
        t => t.to_string(),
    }
}

/// A range covering `values` with a margin, never empty.
#[must_use]
pub fn padded_range(values: impl Iterator<Item = f64>, min_span: f64) -> std::ops::Range<f64> {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return -min_span / 2.0..min_span / 2.0;
    }
    let mid = 0.5 * (lo + hi);
    let half = (0.5 * (hi - lo)).max(min_span / 2.0) * 1.08;
    mid - half..mid + half
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn ticks_have_no_negative_zero() {
        assert_eq!(tick_label(-0.0), "0");
        assert_eq!(tick_label(-1e-17), "0");
        assert_eq!(tick_label(-0.0004), "0");
        assert_eq!(tick_label(2.5), "2.5");
        assert_eq!(tick_label(-120.0), "-120");
        assert_eq!(tick_label(0.125), "0.125");
    }

    proptest! {
        /// Decimation keeps every column's extremes, in time order, never
        /// more than two points per column, and breaks the line exactly at
        /// the gaps that span a column boundary.
        #[test]
        fn decimation_keeps_extremes(
            ys in proptest::collection::vec(-100.0..100.0f64, 1..500),
            gap_at in 0usize..500,
        ) {
            let points: Vec<(f64, f64)> =
                ys.iter().enumerate().map(|(i, &y)| (i as f64, y)).collect();
            let columns = points.len().div_ceil(10);
            let window = 0.0..(10 * columns) as f64;
            let mut line = Decimator::new(&window, columns);
            for (i, &(t, y)) in points.iter().enumerate() {
                line.push(t, y, i != gap_at);
            }
            let lines = line.lines();
            let out: Vec<(f64, f64)> = lines.iter().flatten().copied().collect();
            prop_assert!(out.windows(2).all(|w| w[0].0 <= w[1].0));
            prop_assert!(out.len() <= 2 * columns);
            for chunk in points.chunks(10) {
                let max = chunk.iter().map(|p| p.1).fold(f64::MIN, f64::max);
                let min = chunk.iter().map(|p| p.1).fold(f64::MAX, f64::min);
                prop_assert!(out.iter().any(|p| p.1 == max));
                prop_assert!(out.iter().any(|p| p.1 == min));
            }
            let breaks = gap_at > 0 && gap_at < points.len() && gap_at % 10 == 0;
            prop_assert_eq!(lines.len(), 1 + usize::from(breaks));
        }
    }

    #[test]
    fn points_outside_a_later_window_go_to_its_end_columns() {
        // Ten 1 s columns from 10 s: before the window is the first column,
        // after it the last; inside, each point is in its own column.
        let mut line = Decimator::new(&(10.0..20.0), 10);
        for (t, y) in [
            (4.0, 1.0),
            (10.5, 2.0),
            (14.5, 3.0),
            (15.5, 4.0),
            (25.0, 5.0),
        ] {
            line.push(t, y, false);
        }
        assert_eq!(
            line.lines(),
            vec![
                vec![(4.0, 1.0), (10.5, 2.0)],
                vec![(14.5, 3.0)],
                vec![(15.5, 4.0)],
                vec![(25.0, 5.0)],
            ]
        );
    }

    #[test]
    fn a_zoomed_line_joins_columns_it_skips() {
        let mut line = Decimator::new(&(0.0..1.0), 100);
        for (t, joins) in [(0.0, false), (0.3, true), (0.6, false), (0.9, true)] {
            line.push(t, t, joins);
        }
        assert_eq!(
            line.lines(),
            vec![vec![(0.0, 0.0), (0.3, 0.3)], vec![(0.6, 0.6), (0.9, 0.9)]]
        );
    }
}
