//! Figures as PNG or SVG files: the seed paper's Figure 6 (time plots of a
//! run) and Figure 8 (wobble modes in the complex plane).
//!
//! Text is drawn with the DejaVu Sans font compiled into the program, so
//! plotting needs no system font libraries; an SVG carries the font with it.

pub mod modes;
mod svg_font;
pub mod timeplot;

use std::io::Write;
use std::path::Path;
use std::sync::Once;

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
                path.display()
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

/// 8-bit RGB pixels, row by row, as a PNG file.
fn encode_png(pixels: &[u8], (w, h): (u32, u32)) -> Result<Vec<u8>, png::EncodingError> {
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

/// At most two points (the lowest and highest) per bucket of `bucket_s`:
/// what a line drawn at the figure's resolution shows, in a file that stays
/// small for hours of data.
#[must_use]
pub fn decimate(points: &[(f64, f64)], bucket_s: f64) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < points.len() {
        let bucket = (points[i].0 / bucket_s).floor();
        let len = points[i..]
            .iter()
            .position(|p| (p.0 / bucket_s).floor() != bucket)
            .unwrap_or(points.len() - i);
        let chunk = &points[i..i + len];
        let lo = chunk.iter().min_by(|a, b| a.1.total_cmp(&b.1));
        let hi = chunk.iter().max_by(|a, b| a.1.total_cmp(&b.1));
        if let (Some(&lo), Some(&hi)) = (lo, hi) {
            if lo == hi {
                out.push(lo);
            } else if lo.0 <= hi.0 {
                out.extend([lo, hi]);
            } else {
                out.extend([hi, lo]);
            }
        }
        i += len;
    }
    out
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
        /// Decimation keeps every bucket's extremes, in time order, and
        /// never more than two points per bucket.
        #[test]
        fn decimation_keeps_extremes(ys in proptest::collection::vec(-100.0..100.0f64, 1..500)) {
            let points: Vec<(f64, f64)> =
                ys.iter().enumerate().map(|(i, &y)| (i as f64, y)).collect();
            let out = decimate(&points, 10.0);
            prop_assert!(out.windows(2).all(|w| w[0].0 <= w[1].0));
            prop_assert!(out.len() <= 2 * (points.len() / 10 + 2));
            for chunk in points.chunks(10) {
                let max = chunk.iter().map(|p| p.1).fold(f64::MIN, f64::max);
                prop_assert!(out.iter().any(|p| p.1 == max));
            }
        }
    }
}
