//! Figures as PNG or SVG files: the seed paper's Figure 6 (time plots of a
//! run) and Figure 8 (wobble modes in the complex plane).
//!
//! Text is drawn with the DejaVu Sans font compiled into the program, so
//! plotting needs no system font libraries; an SVG carries the font with it.

pub mod key;
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

/// A figure that can draw itself on any plotters backend, at any size.
pub trait Figure {
    /// The figure's own size, px, when `--size` does not give one.
    fn size_px(&self) -> (u32, u32);
    /// Draws the figure on `root`, laid out to `root`'s size.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String>;
}

/// Layout pixels per inch: a figure is laid out in CSS pixels, so an SVG
/// opens at its size and a PNG at `--dpi 96` has one pixel per layout pixel.
pub const PX_PER_INCH: f64 = 96.0;

/// `--size` and `--dpi`, shared by every command that draws a figure.
#[derive(clap::Args, Clone, Debug)]
pub struct FigureArgs {
    /// Figure size, `WxH`, in layout pixels (96 to the inch) or with a unit
    /// for both: `1400x900`, `7x4.5in`, `18x11cm`, `180x110mm`. Text keeps
    /// its size, so a larger figure holds more detail, not larger letters.
    /// Default: the figure's own size.
    #[arg(long, value_name = "WxH[UNIT]", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// PNG resolution, dots per inch: 96 draws one pixel per layout pixel,
    /// 300 a print-ready image of the same figure. SVG is drawn without a
    /// resolution and ignores it.
    #[arg(long, value_name = "DPI", default_value_t = PX_PER_INCH, value_parser = parse_dpi)]
    pub dpi: f64,
}

/// The smallest figure drawn, layout px: below it axes and keys overlap.
pub const MIN_SIZE_PX: (u32, u32) = (480, 320);
/// The largest PNG drawn, pixels: a typing slip must not ask for gigabytes.
const MAX_PNG_PIXELS: f64 = 200e6;

/// `--size`: `WxH` with an optional unit (`px`, `in`, `cm`, `mm`), in
/// layout pixels.
///
/// # Errors
/// What is wrong with `text`, with an example.
pub fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let t = text.trim().to_ascii_lowercase();
    let (number, px_per_unit) = [
        ("px", 1.0),
        ("in", PX_PER_INCH),
        ("cm", PX_PER_INCH / 2.54),
        ("mm", PX_PER_INCH / 25.4),
    ]
    .into_iter()
    .find_map(|(unit, scale)| t.strip_suffix(unit).map(|n| (n, scale)))
    .unwrap_or((&t, 1.0));
    let bad = |why: &str| {
        format!("{why}: give WxH with an optional unit (px, in, cm, mm), as 1400x900 or 7x4.5in")
    };
    let (w, h) = number
        .split_once('x')
        .ok_or_else(|| bad("no `x` between width and height"))?;
    let side = |v: &str| -> Result<f64, String> {
        let v: f64 = v
            .trim()
            .parse()
            .map_err(|_| bad(&format!("`{}` is not a number", v.trim())))?;
        Ok(v * px_per_unit)
    };
    let (w, h) = (side(w)?, side(h)?);
    let (min_w, min_h) = MIN_SIZE_PX;
    if !(w >= f64::from(min_w) && h >= f64::from(min_h)) {
        return Err(format!(
            "{text} is {w:.0}x{h:.0} px; figures are at least {min_w}x{min_h} px ({:.1}x{:.1} in)",
            f64::from(min_w) / PX_PER_INCH,
            f64::from(min_h) / PX_PER_INCH
        ));
    }
    if w * h > MAX_PNG_PIXELS {
        return Err(format!(
            "{text} is {w:.0}x{h:.0} px, larger than any figure needs"
        ));
    }
    Ok((w.round() as u32, h.round() as u32))
}

/// `--dpi`: 24 to 2400.
///
/// # Errors
/// `text` is not a number in that range.
pub fn parse_dpi(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(dpi) if (24.0..=2400.0).contains(&dpi) => Ok(dpi),
        _ => Err(format!(
            "{text}: give dots per inch from 24 to 2400 (300 for print)"
        )),
    }
}

impl Default for FigureArgs {
    /// Each figure's own size at 96 dpi.
    fn default() -> Self {
        Self {
            size: None,
            dpi: PX_PER_INCH,
        }
    }
}

impl FigureArgs {
    /// The size to draw `figure` at.
    #[must_use]
    pub fn size_of(&self, figure: &impl Figure) -> (u32, u32) {
        self.size.unwrap_or_else(|| figure.size_px())
    }

    /// The PNG's size in pixels for a figure of `size` layout px.
    ///
    /// # Errors
    /// The image would be larger than any figure needs.
    pub fn png_pixels(&self, (w, h): (u32, u32)) -> Result<(u32, u32), String> {
        let scale = self.dpi / PX_PER_INCH;
        let (pw, ph) = (f64::from(w) * scale, f64::from(h) * scale);
        if pw * ph > MAX_PNG_PIXELS {
            return Err(format!(
                "{pw:.0}x{ph:.0} pixels at {} dpi is larger than any figure needs; \
                 lower --dpi or --size",
                self.dpi
            ));
        }
        Ok(((pw.round() as u32).max(1), (ph.round() as u32).max(1)))
    }
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

/// Draws `figure` into `out`, PNG or SVG by the output's extension, at
/// `look`'s size and resolution, and commits it. The image is drawn in
/// memory (plotters' own file writing would bypass the atomic output and
/// report errors as debug text).
pub fn render(figure: &impl Figure, mut out: Output, look: &FigureArgs) -> Result<(), CliError> {
    let kind = ImageKind::of(out.name())?;
    let bytes = draw(figure, kind, look)
        .map_err(|e| CliError::file(out.name(), format!("cannot draw the plot: {e}")))?;
    out.write_all(&bytes).map_err(|e| out.error(e))?;
    out.commit()
}

/// The figure as an image file's bytes. A PNG is the SVG rasterised by
/// resvg: anti-aliased at any resolution, and the same drawing as the SVG.
fn draw(figure: &impl Figure, kind: ImageKind, look: &FigureArgs) -> Result<Vec<u8>, String> {
    let size = look.size_of(figure);
    let svg = svg_at(figure, size)?;
    match kind {
        ImageKind::Png => rasterise(&svg, size, look.png_pixels(size)?),
        ImageKind::Svg => Ok(svg_font::embed(&svg, FONT, FONT_BYTES)?.into_bytes()),
    }
}

/// `figure` drawn at `size` as SVG text, without an embedded font.
fn svg_at(figure: &impl Figure, size: (u32, u32)) -> Result<String, String> {
    register_font();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        figure.draw(&root)?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(svg)
}

/// `svg` (laid out at `size` px) as a PNG of `pixels`, over white.
fn rasterise(svg: &str, size: (u32, u32), pixels: (u32, u32)) -> Result<Vec<u8>, String> {
    use resvg::{tiny_skia, usvg};
    static FONTS: std::sync::OnceLock<std::sync::Arc<usvg::fontdb::Database>> =
        std::sync::OnceLock::new();
    let fonts = FONTS.get_or_init(|| {
        let mut db = usvg::fontdb::Database::new();
        db.load_font_data(FONT_BYTES.to_vec());
        std::sync::Arc::new(db)
    });
    // Every text element names its family (plotters writes it), so the
    // options need only the font itself.
    let options = usvg::Options {
        fontdb: fonts.clone(),
        ..usvg::Options::default()
    };
    let tree = usvg::Tree::from_str(svg, &options).map_err(|e| e.to_string())?;
    let (w, h) = pixels;
    let mut pixmap = tiny_skia::Pixmap::new(w, h).ok_or("the image has no pixels")?;
    pixmap.fill(tiny_skia::Color::WHITE);
    let scale = |px: u32, layout: u32| px as f32 / layout.max(1) as f32;
    let transform = tiny_skia::Transform::from_scale(scale(w, size.0), scale(h, size.1));
    resvg::render(&tree, transform, &mut pixmap.as_mut());
    // Every pixel is opaque over the white fill: premultiplied RGBA is RGB.
    let rgb: Vec<u8> = pixmap
        .data()
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    encode_png(&rgb, pixels).map_err(|e| e.to_string())
}

/// `figure` as SVG text to place inside a page, without the embedded font
/// (the page names the font and the browser supplies one): a report holds
/// several figures and would otherwise carry the font once per figure.
///
/// # Errors
/// The backend's error, as text.
pub fn svg_inline(figure: &impl Figure) -> Result<String, String> {
    svg_at(figure, figure.size_px())
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

/// A chart of `x_range` by `y_range` on `area`, `margin_px` from its edge
/// and `key_px` from its right edge (room for [`draw_key_beside`]), with
/// its mesh drawn: `x_desc` and `y_desc` as the axes' names and
/// [`tick_label`] ticks. The axes of the margin and mode figures.
///
/// # Errors
/// The backend's error, as text.
pub fn numbers_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    (margin_px, key_px): (u32, u32),
    (x_range, y_range): (Range<f64>, Range<f64>),
    (x_desc, y_desc): (&str, &str),
) -> Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>, String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let mut chart = ChartBuilder::on(area)
        .margin(margin_px)
        .margin_right(margin_px.max(key_px))
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
    fn sizes_are_layout_pixels_in_any_unit() {
        assert_eq!(parse_size("1400x900"), Ok((1400, 900)));
        assert_eq!(parse_size("1400x900px"), Ok((1400, 900)));
        // 96 to the inch, 2.54 cm to the inch, rounded to the pixel.
        assert_eq!(parse_size(" 7X5IN "), Ok((672, 480)));
        assert_eq!(parse_size("17x12cm"), Ok((643, 454)));
        assert_eq!(parse_size("180x110mm"), Ok((680, 416)));
        assert_eq!(parse_size("480x320"), Ok(MIN_SIZE_PX));
        assert_eq!(parse_size("14142x14142"), Ok((14142, 14142)));
        // The largest figure itself is drawn.
        assert_eq!(parse_size("20000x10000"), Ok((20000, 10000)));
        for (text, says) in [
            ("479x900", "at least 480x320"),
            ("480x319", "at least 480x320"),
            ("NaNx900", "at least 480x320"),
            ("7x", "is not a number"),
            ("7by5", "no `x`"),
            ("14143x14143", "larger than any figure needs"),
        ] {
            let err = parse_size(text).unwrap_err();
            assert!(err.contains(says), "{text}: {err}");
        }
    }

    #[test]
    fn resolutions_run_from_24_to_2400_dpi() {
        assert_eq!(parse_dpi("24"), Ok(24.0));
        assert_eq!(parse_dpi(" 300 "), Ok(300.0));
        assert_eq!(parse_dpi("2400"), Ok(2400.0));
        for text in ["23.9", "2400.1", "NaN", "-96", "x"] {
            assert!(
                parse_dpi(text).unwrap_err().contains("24 to 2400"),
                "{text}"
            );
        }
    }

    #[test]
    fn a_png_has_dpi_over_96_pixels_per_layout_pixel() {
        let at = |dpi: f64| FigureArgs { size: None, dpi };
        assert_eq!(at(96.0).png_pixels((700, 500)), Ok((700, 500)));
        assert_eq!(at(300.0).png_pixels((700, 500)), Ok((2188, 1563)));
        assert_eq!(at(48.0).png_pixels((480, 320)), Ok((240, 160)));
        assert_eq!(at(96.0).png_pixels((14142, 14142)), Ok((14142, 14142)));
        assert_eq!(at(96.0).png_pixels((20000, 10000)), Ok((20000, 10000)));
        assert_eq!(at(192.0).png_pixels((10000, 5000)), Ok((20000, 10000)));
        let err = at(1200.0).png_pixels((10000, 10000)).unwrap_err();
        assert!(err.contains("lower --dpi or --size"), "{err}");
        assert!(at(96.0).png_pixels((14143, 14143)).is_err());
    }

    struct Blank;

    /// White, with one word in large text.
    struct Word;

    impl Figure for Word {
        fn size_px(&self) -> (u32, u32) {
            (480, 320)
        }

        fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
            root.fill(&WHITE).map_err(|e| e.to_string())?;
            root.draw(&Text::new("WWW", (40, 100), (FONT, 120)))
                .map_err(|e| e.to_string())
        }
    }

    #[test]
    fn png_text_is_drawn_with_the_bundled_font() {
        let png = draw(&Word, ImageKind::Png, &FigureArgs::default()).unwrap();
        let mut reader = png::Decoder::new(std::io::Cursor::new(png))
            .read_info()
            .unwrap();
        let mut pixels = vec![0; reader.output_buffer_size()];
        reader.next_frame(&mut pixels).unwrap();
        // Three capital Ws at 120 px cover thousands of pixels, with
        // anti-aliased edges; no font, no glyph: a white page.
        let dark = pixels.chunks_exact(3).filter(|p| p[0] < 64).count();
        let edge = pixels
            .chunks_exact(3)
            .filter(|p| (64..192).contains(&p[0]))
            .count();
        assert!(dark > 5000, "{dark} dark pixels");
        assert!(edge > 200, "{edge} edge pixels");
    }

    impl Figure for Blank {
        fn size_px(&self) -> (u32, u32) {
            (640, 400)
        }

        fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
            root.fill(&WHITE).map_err(|e| e.to_string())?;
            // A black bar across the middle third, top to bottom.
            let (w, h) = root.dim_in_pixel();
            let (w, h) = (i32::try_from(w).unwrap(), i32::try_from(h).unwrap());
            root.draw(&Rectangle::new(
                [(w / 3, 0), (2 * w / 3, h)],
                BLACK.filled(),
            ))
            .map_err(|e| e.to_string())
        }
    }

    #[test]
    fn the_png_is_the_svg_drawn_at_the_size_and_resolution_asked() {
        let look = |size: Option<(u32, u32)>, dpi: f64| FigureArgs { size, dpi };
        assert_eq!(look(None, 96.0).size_of(&Blank), (640, 400));
        assert_eq!(look(Some((900, 500)), 96.0).size_of(&Blank), (900, 500));
        let png = draw(&Blank, ImageKind::Png, &look(Some((900, 500)), 192.0)).unwrap();
        let mut reader = png::Decoder::new(std::io::Cursor::new(png))
            .read_info()
            .unwrap();
        let mut pixels = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut pixels).unwrap();
        assert_eq!((info.width, info.height), (1800, 1000));
        assert_eq!(info.color_type, png::ColorType::Rgb);
        // White left and right, black in the middle third: the drawing is
        // scaled to the pixels, not cropped or tiled.
        let at = |x: usize, y: usize| &pixels[(y * 1800 + x) * 3..][..3];
        assert_eq!(at(100, 500), [255, 255, 255]);
        assert_eq!(at(900, 10), [0, 0, 0]);
        assert_eq!(at(900, 990), [0, 0, 0]);
        assert_eq!(at(1700, 500), [255, 255, 255]);
        let svg =
            String::from_utf8(draw(&Blank, ImageKind::Svg, &look(None, 300.0)).unwrap()).unwrap();
        assert!(svg.contains("width=\"640\" height=\"400\""), "{svg:.300}");
        assert!(svg.contains("@font-face"), "{svg:.300}");
    }

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
