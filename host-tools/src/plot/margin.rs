//! The campaign's damping trend: every kick's sigma against its speed with
//! its error bar (two standard uncertainties), the robust trend and its
//! 95 % band carried forward to zero, the predicted wobble speed with its
//! interval, and the model's curve when one was fitted: the seed paper's
//! Figure 8 (left panel) extended forward.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::key::{self, Swatch};
use super::modes::{DOT_PX, ZERO_LINE_COLOUR};
use super::{numbers_chart, padded_range, titled_page, Figure};
use crate::analysis::margin::{Margin, Trend};

/// One kick as drawn.
#[derive(Clone, Debug, PartialEq)]
pub struct KickDot {
    /// Speed, m/s.
    pub speed_mps: f64,
    /// Growth rate, 1/s.
    pub sigma_per_s: f64,
    /// Standard uncertainty, 1/s.
    pub sd_per_s: f64,
    /// Whether the fit used it.
    pub used: bool,
}

/// The figure.
pub struct MarginPlot {
    /// The kicks.
    pub kicks: Vec<KickDot>,
    /// The prediction.
    pub margin: Margin,
    /// The fitted model's sigma against speed, if any: `(u, sigma)`.
    pub model_curve: Option<Vec<(f64, f64)>>,
    /// The fitted model's wobble speed and interval, if any.
    pub model_speed: Option<(f64, [Option<f64>; 2])>,
}

const SIZE_PX: (u32, u32) = (1000, 640);
const USED: RGBColor = RGBColor(0x1f, 0x4e, 0x9a);
const REJECTED: RGBColor = RGBColor(0xd6, 0x27, 0x28);
const FIT: RGBColor = RGBColor(0x20, 0x20, 0x20);
const BAND: RGBColor = RGBColor(0xc8, 0xd4, 0xe8);
const MODEL: RGBColor = RGBColor(0x2c, 0xa0, 0x2c);
const CROSSING: RGBColor = RGBColor(0xff, 0x7f, 0x0e);
const RIDE: RGBColor = RGBColor(0x94, 0x67, 0xbd);
const NEXT: RGBColor = RGBColor(0x8c, 0x56, 0x4b);
/// Points on the line and band.
const STEPS: usize = 120;

impl MarginPlot {
    /// The speed axis: the kicks, the prediction and its interval (an open
    /// end drawn to the axis' edge), the model's crossing.
    fn x_range(&self) -> std::ops::Range<f64> {
        let m = &self.margin;
        let kicks = self.kicks.iter().map(|k| k.speed_mps);
        let top = self.kicks.iter().map(|k| k.speed_mps).fold(0.0, f64::max);
        // Never more than twice the fastest kick: a far prediction is
        // written, not drawn.
        let cap = 2.0 * top.max(1.0);
        let ahead = [
            m.wobble_speed_mps,
            m.ci95_mps[0],
            m.ci95_mps[1],
            m.advice.next_pass_max_mps,
            self.model_speed.map(|s| s.0),
        ]
        .into_iter()
        .flatten()
        .map(|v| v.min(cap));
        let r = padded_range(kicks.chain(ahead), 1.0);
        r.start.max(0.0)..r.end
    }

    /// Over the kicks the fit's own band; beyond the fastest, the band
    /// for a wobble speed there (the bend allowed for), whose crossings of
    /// zero are the interval.
    fn band(&self, u: f64) -> Option<(f64, f64, f64)> {
        let top = self.kicks.iter().map(|k| k.speed_mps).fold(0.0, f64::max);
        if u <= top {
            self.margin.fit_band(u)
        } else {
            self.margin.band(u)
        }
    }
}

impl Figure for MarginPlot {
    fn size_px(&self) -> (u32, u32) {
        SIZE_PX
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        let root = titled_page(root, "Damping trend of the wobble mode")?;
        let x_range = self.x_range();
        let us: Vec<f64> = (0..=STEPS)
            .map(|i| x_range.start + (x_range.end - x_range.start) * i as f64 / STEPS as f64)
            .collect();
        let band: Vec<(f64, (f64, f64, f64))> = us
            .iter()
            .filter_map(|&u| self.band(u).map(|b| (u, b)))
            .collect();
        // The kicks, the line and zero set the scale; an error bar longer
        // than that is cut at the edge.
        let dots = self.kicks.iter().map(|k| k.sigma_per_s);
        // The model's curve only where the figure shows speeds.
        let curve: Vec<(f64, f64)> = self
            .model_curve
            .iter()
            .flatten()
            .copied()
            .filter(|p| x_range.contains(&p.0))
            .collect();
        let model = curve.iter().map(|p| p.1);
        let line = band.iter().map(|b| b.1 .0);
        let y_range = padded_range(dots.chain(model).chain(line).chain([0.0]), 1.0);
        // Room for the longest key any prediction can have, so that the
        // figures of two campaigns share their layout.
        let key_px = key::width_px(&root, &KEY_LABELS)?;
        let mut entries: Vec<(String, Swatch)> = Vec::new();
        let mut chart = numbers_chart(
            &root,
            (MARGIN_PX, key_px),
            (x_range.clone(), y_range.clone()),
            ("speed (m/s)", "growth rate sigma (1/s)"),
        )?;
        let clip = |y: f64| y.clamp(y_range.start, y_range.end);
        // The 95 % band of the line, then the interval of the crossing.
        if !band.is_empty() {
            let mut outline: Vec<(f64, f64)> = band.iter().map(|(u, b)| (*u, clip(b.2))).collect();
            outline.extend(band.iter().rev().map(|(u, b)| (*u, clip(b.1))));
            chart
                .draw_series(std::iter::once(Polygon::new(
                    outline,
                    BAND.mix(0.6).filled(),
                )))
                .map_err(err)?;
            entries.push((BAND_LABEL.into(), Swatch::Fill(BAND.to_rgba())));
        }
        if let [Some(lo), hi] = self.margin.ci95_mps {
            let hi = hi.unwrap_or(x_range.end).min(x_range.end);
            let lo = lo.max(x_range.start);
            if hi > lo {
                chart
                    .draw_series(std::iter::once(Rectangle::new(
                        [(lo, y_range.start), (hi, y_range.end)],
                        CROSSING.mix(0.12).filled(),
                    )))
                    .map_err(err)?;
                entries.push((INTERVAL_LABEL.into(), Swatch::Fill(CROSSING.mix(0.3))));
            }
        }
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(x_range.start, 0.0), (x_range.end, 0.0)],
                ZERO_LINE_COLOUR.stroke_width(1),
            )))
            .map_err(err)?;
        if !band.is_empty() {
            let fit: Vec<(f64, f64)> = band.iter().map(|(u, b)| (*u, b.0)).collect();
            chart
                .draw_series(LineSeries::new(fit, FIT.stroke_width(2)))
                .map_err(err)?;
            let label = match self.margin.trend {
                Trend::Line => LINE_LABEL,
                Trend::Quadratic => "robust quadratic",
            };
            entries.push((label.into(), Swatch::line(FIT, 2)));
        }
        if let Some(w) = self.margin.wobble_speed_mps.filter(|w| x_range.contains(w)) {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(w, y_range.start), (w, y_range.end)],
                    CROSSING.stroke_width(2),
                )))
                .map_err(err)?;
            entries.push((
                format!("predicted wobble speed {w:.2} m/s"),
                Swatch::line(CROSSING, 2),
            ));
        }
        for (speed, colour, what) in [
            (self.margin.advice.ride_below_mps, RIDE, "ride below"),
            (
                self.margin.advice.next_pass_max_mps,
                NEXT,
                "next pass at most",
            ),
        ] {
            let Some(v) = speed.filter(|v| x_range.contains(v)) else {
                continue;
            };
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(v, y_range.start), (v, y_range.end)],
                    colour.stroke_width(2),
                )))
                .map_err(err)?;
            entries.push((format!("{what} {v:.2} m/s"), Swatch::line(colour, 2)));
        }
        if self.model_curve.is_some() {
            let label = self.model_speed.map_or("fitted model".to_string(), |s| {
                format!("fitted model, wobble speed {:.2} m/s", s.0)
            });
            chart
                .draw_series(LineSeries::new(
                    curve.iter().map(|&(u, s)| (u, clip(s))),
                    MODEL.stroke_width(2),
                ))
                .map_err(err)?;
            entries.push((label, Swatch::line(MODEL, 2)));
        }
        for (colour, used, label) in [
            (USED, true, "kick (±2 SD)"),
            (REJECTED, false, "kick rejected"),
        ] {
            let kicks: Vec<&KickDot> = self.kicks.iter().filter(|k| k.used == used).collect();
            if kicks.is_empty() {
                continue;
            }
            chart
                .draw_series(kicks.iter().map(|k| {
                    PathElement::new(
                        vec![
                            (k.speed_mps, clip(k.sigma_per_s - 2.0 * k.sd_per_s)),
                            (k.speed_mps, clip(k.sigma_per_s + 2.0 * k.sd_per_s)),
                        ],
                        colour.stroke_width(1),
                    )
                }))
                .map_err(err)?;
            chart
                .draw_series(kicks.iter().map(|k| {
                    Circle::new(
                        (k.speed_mps, clip(k.sigma_per_s)),
                        DOT_PX - 1,
                        colour.filled(),
                    )
                }))
                .map_err(err)?;
            entries.push((label.into(), Swatch::Dot(colour, DOT_PX - 1)));
        }
        key::draw(&root, chart.plotting_area(), key_px, &entries)
    }
}

/// Space around the chart, px.
const MARGIN_PX: u32 = 16;
const BAND_LABEL: &str = "95 % band: the fit's; beyond the kicks, with the bend";
const INTERVAL_LABEL: &str = "wobble speed, 95 % interval";
const LINE_LABEL: &str = "robust line, bent by the shape prior";
/// The longest entries the key can hold (speeds as wide as they are drawn).
const KEY_LABELS: [&str; 5] = [
    BAND_LABEL,
    INTERVAL_LABEL,
    LINE_LABEL,
    "predicted wobble speed 00.00 m/s",
    "fitted model, wobble speed 00.00 m/s",
];
