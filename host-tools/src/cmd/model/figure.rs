//! Eigenvalues against speed in the seed paper's Figure 4 layout: the real
//! part (1/s) above, the imaginary part as a frequency (Hz) below, one
//! colour per mode. Several sweeps can share the figure, told apart by line
//! style (standard thick, half thin, double dotted as in Figures 7, 9-11),
//! and measured points can be laid over it (Figure 8).

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use wobble_model::sweep::REAL_TOL;
use wobble_model::{Mode, Sweep};

use crate::plot::key::{self, Swatch};
use crate::plot::{padded_range, Figure, FONT};

/// How a sweep's lines are drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Line {
    /// The standard: solid, thick.
    Thick,
    /// Solid, thin.
    Thin,
    /// Dotted.
    Dotted,
    /// Dashed (a second model).
    Dashed,
}

impl Line {
    /// Stroke width, px, and dash and gap lengths of a broken line.
    fn stroke(self) -> (u32, Option<(u32, u32)>) {
        match self {
            Self::Thick => (3, None),
            Self::Thin => (1, None),
            Self::Dotted => (2, Some((2, 4))),
            Self::Dashed => (2, Some((8, 6))),
        }
    }
}

/// One sweep on the figure.
pub struct Layer {
    /// Legend text.
    pub label: String,
    /// Its eigenvalues.
    pub sweep: Sweep,
    /// Its line style.
    pub line: Line,
}

/// A measured point: speed, real part, frequency, and whether it may be
/// fitted (censored points are drawn open).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measured {
    /// Speed at onset, m/s.
    pub speed_mps: f64,
    /// Growth rate sigma, 1/s.
    pub sigma_per_s: f64,
    /// Frequency, Hz.
    pub freq_hz: f64,
    /// Censored: drawn open, never fitted.
    pub censored: bool,
}

/// The figure.
pub struct EigenFigure {
    /// Title.
    pub title: String,
    /// Sweeps, drawn in order.
    pub layers: Vec<Layer>,
    /// Modes drawn (others left out).
    pub modes: Vec<Mode>,
    /// Measured points.
    pub measured: Vec<Measured>,
    /// Critical speeds marked on the real part's zero line: the mode and
    /// the speed, m/s.
    pub critical: Vec<(Mode, f64)>,
}

/// The critical speeds of `model` found on `sweep` whose mode is among
/// `modes`, to mark on the figure.
#[must_use]
pub fn critical_marks(
    model: &wobble_model::Model,
    sweep: &Sweep,
    modes: &[Mode],
) -> Vec<(Mode, f64)> {
    wobble_model::critical_speeds(model, sweep)
        .into_iter()
        .filter(|c| modes.contains(&c.mode))
        .map(|c| (c.mode, c.speed_mps))
        .collect()
}

fn colour(mode: Mode) -> RGBColor {
    match mode {
        Mode::Wobble => RGBColor(0xd6, 0x27, 0x28),
        Mode::Weave => RGBColor(0x1f, 0x4e, 0x9a),
        Mode::Capsize => RGBColor(0x2c, 0xa0, 0x2c),
        Mode::Castering => RGBColor(0xff, 0x7f, 0x0e),
        Mode::Lean => RGBColor(0x94, 0x67, 0xbd),
        Mode::Sway => RGBColor(0x17, 0xbe, 0xcf),
        Mode::Twist => RGBColor(0x8c, 0x56, 0x4b),
        Mode::Other => RGBColor(0x9f, 0x9f, 0x9f),
    }
}

/// Points of one panel for a branch, split where the value is missing.
fn runs(speeds: &[f64], values: impl Iterator<Item = Option<f64>>) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for (&u, v) in speeds.iter().zip(values) {
        match v {
            Some(v) if v.is_finite() => out.last_mut().into_iter().for_each(|r| r.push((u, v))),
            _ => out.push(Vec::new()),
        }
    }
    out.retain(|r| r.len() > 1);
    out
}

/// Shortest segment of a wide line, pixels.
const MIN_SEGMENT_PX: i32 = 16;

/// The points of `run` at least [`MIN_SEGMENT_PX`] from the last one kept
/// (the ends always kept). plotters fills a line wider than one pixel as a
/// polygon on whole-pixel corners offset from each segment's direction, so a
/// fine sweep's 1-3 px segments, whose directions the rounding scatters, give
/// it a stair-stepped edge; the curves are smooth at this scale.
fn spaced(run: Vec<(f64, f64)>, px: impl Fn(&(f64, f64)) -> (i32, i32)) -> Vec<(f64, f64)> {
    let Some(&last) = run.last() else {
        return run;
    };
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(run.len());
    for p in run {
        let far = out.last().is_none_or(|q| {
            let (a, b) = (px(q), px(&p));
            (a.0 - b.0).abs().max((a.1 - b.1).abs()) >= MIN_SEGMENT_PX
        });
        if far {
            out.push(p);
        }
    }
    if out.last() != Some(&last) {
        out.push(last);
    }
    out
}

impl EigenFigure {
    fn branches(&self) -> impl Iterator<Item = (&Layer, &wobble_model::Branch)> {
        self.layers.iter().flat_map(move |l| {
            l.sweep
                .branches
                .iter()
                .filter(|b| self.modes.contains(&b.mode))
                .map(move |b| (l, b))
        })
    }

    /// The key's name of `mode` drawn from `layer`.
    fn key_name(&self, mode: Mode, layer: &Layer) -> String {
        if self.layers.len() > 1 {
            format!("{mode}: {}", layer.label)
        } else {
            mode.to_string()
        }
    }

    /// Every name the key holds, in order.
    fn key_names(&self) -> Vec<String> {
        let mut names: Vec<String> = Vec::new();
        for (layer, branch) in self.branches() {
            let name = self.key_name(branch.mode, layer);
            if !names.contains(&name) {
                names.push(name);
            }
        }
        if !self.measured.is_empty() {
            names.push(MEASURED_LABEL.into());
        }
        names
    }

    /// One panel: the real parts with the key beside them, or the
    /// frequencies; both leave `key_px` on the right so their speed axes
    /// line up.
    fn panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        frequency: bool,
        key_px: u32,
    ) -> Result<(), String> {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        let pick = |v: wobble_model::Complex<f64>| {
            if frequency {
                (v.im > REAL_TOL).then_some(v.im / std::f64::consts::TAU)
            } else {
                Some(v.re)
            }
        };
        let speeds = self
            .layers
            .iter()
            .flat_map(|l| l.sweep.speeds_mps.iter().copied());
        let x = padded_range(speeds, 1.0);
        let x = x.start.max(0.0)..x.end;
        let ys = self
            .branches()
            .flat_map(|(_, b)| b.values.iter().filter_map(|v| pick(*v)))
            .chain(
                self.measured
                    .iter()
                    .map(|m| if frequency { m.freq_hz } else { m.sigma_per_s }),
            )
            // The zero line of the real part is what the figure is about.
            .chain((!frequency).then_some(0.0));
        let y = padded_range(ys, 1.0);
        let (caption, y_desc) = if frequency {
            ("", "frequency (Hz)")
        } else {
            (self.title.as_str(), "real part (1/s)")
        };
        let mut chart = ChartBuilder::on(area)
            .caption(caption, (FONT, 20))
            .margin(12)
            .margin_right(12.max(key_px))
            .x_label_area_size(36)
            .y_label_area_size(56)
            .build_cartesian_2d(x.clone(), y)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("forward speed (m/s)")
            .y_desc(y_desc)
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 15))
            .draw()
            .map_err(err)?;
        if !frequency {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(x.start, 0.0), (x.end, 0.0)],
                    BLACK.stroke_width(1),
                )))
                .map_err(err)?;
        }
        let mut entries: Vec<(String, Swatch)> = Vec::new();
        for (layer, branch) in self.branches() {
            let c = colour(branch.mode);
            for run in runs(
                &layer.sweep.speeds_mps,
                branch.values.iter().map(|v| pick(*v)),
            ) {
                let (width, dashes) = layer.line.stroke();
                let style = c.stroke_width(width);
                match (layer.line, dashes) {
                    (Line::Thick, _) => chart
                        .draw_series(LineSeries::new(
                            spaced(run, |p| chart.backend_coord(p)),
                            style,
                        ))
                        .map(drop),
                    (_, Some((dash, gap))) => chart
                        .draw_series(DashedLineSeries::new(run, dash, gap, style))
                        .map(drop),
                    (_, None) => chart.draw_series(LineSeries::new(run, style)).map(drop),
                }
                .map_err(err)?;
                let name = self.key_name(branch.mode, layer);
                if !frequency && !entries.iter().any(|e| e.0 == name) {
                    // The key's swatch is drawn as the line is: dotted and
                    // dashed layers must be told apart there too.
                    let swatch = Swatch::Line {
                        colour: c,
                        width,
                        dashes,
                    };
                    entries.push((name, swatch));
                }
            }
        }
        let dot = |m: &Measured| {
            let at = (
                m.speed_mps,
                if frequency { m.freq_hz } else { m.sigma_per_s },
            );
            let style = if m.censored {
                BLACK.stroke_width(2)
            } else {
                BLACK.filled()
            };
            Circle::new(at, 4, style)
        };
        if !frequency {
            // Each critical speed: a mark on the zero line in its mode's
            // colour, named with its speed above it.
            for &(mode, v) in &self.critical {
                let c = colour(mode);
                chart
                    .draw_series(std::iter::once(TriangleMarker::new(
                        (v, 0.0),
                        7,
                        c.filled(),
                    )))
                    .map_err(err)?;
                chart
                    .draw_series(std::iter::once(Text::new(
                        format!("{mode} {v:.2} m/s"),
                        (v, 0.0),
                        (FONT, 13)
                            .into_font()
                            .color(&c)
                            .pos(Pos::new(HPos::Left, VPos::Bottom)),
                    )))
                    .map_err(err)?;
            }
        }
        if !self.measured.is_empty() {
            chart
                .draw_series(self.measured.iter().map(dot))
                .map_err(err)?;
            entries.push((MEASURED_LABEL.into(), Swatch::Dot(BLACK, 4)));
        }
        if frequency {
            return Ok(());
        }
        key::draw(area, chart.plotting_area(), key_px, &entries)
    }
}

/// The key's name for measured points.
const MEASURED_LABEL: &str = "measured (open: censored)";

impl Figure for EigenFigure {
    fn size_px(&self) -> (u32, u32) {
        (1200, 900)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let key_px = key::width_px(root, &self.key_names())?;
        // The real parts, with the title and the key, take a little more
        // than half the height.
        let (_, h) = root.dim_in_pixel();
        let (top, bottom) = root.split_vertically(h * 8 / 15);
        self.panel(&top, false, key_px)?;
        self.panel(&bottom, true, key_px)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fine sweep's points 1 px apart become segments of at least 16 px
    /// (the last one may be shorter), with both ends kept.
    #[test]
    fn wide_lines_get_segments_of_at_least_16_px() {
        let run: Vec<(f64, f64)> = (0..=100)
            .map(|i| (f64::from(i), (f64::from(i) * 0.1).sin()))
            .collect();
        let px = |p: &(f64, f64)| (p.0.round() as i32, (p.1 * 50.0).round() as i32);
        let out = spaced(run.clone(), px);
        assert_eq!(out.first(), run.first());
        assert_eq!(out.last(), run.last());
        assert!(out.len() < run.len() / 4, "{} points", out.len());
        for w in out[..out.len() - 1].windows(2) {
            let (a, b) = (px(&w[0]), px(&w[1]));
            assert!((a.0 - b.0).abs().max((a.1 - b.1).abs()) >= MIN_SEGMENT_PX);
        }
        assert!(spaced(Vec::new(), px).is_empty());
    }
}
