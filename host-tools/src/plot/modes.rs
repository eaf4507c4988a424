//! The seed paper's Figure 8: every wobble episode as a point in the complex
//! plane, real part sigma (growth rate) against imaginary part 2 pi f, one
//! colour per run. Right of the zero line the wobble grew by itself.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{padded_range, Figure, FONT};
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

/// Figure 8 over any number of runs.
pub struct ModePlot {
    runs: Vec<(String, Vec<Episode>)>,
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
}

impl Figure for ModePlot {
    fn size_px(&self) -> (u32, u32) {
        (900, 700)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        root.fill(&WHITE).map_err(err)?;
        // Zero stays in view: it is the line the figure is about.
        let x = padded_range(self.all().map(|e| e.sigma_per_s).chain([0.0]), 2.0);
        let y = padded_range(self.all().map(Episode::omega_rad_s), 10.0);
        let mut chart = ChartBuilder::on(root)
            .caption(
                "Wobble modes (filled: unstable, open: stable, grey: cut by a gap)",
                (FONT, 20),
            )
            .margin(16)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(x, y.clone())
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(X_LABEL)
            .y_desc(Y_LABEL)
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 15))
            .draw()
            .map_err(err)?;
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(0.0, y.start), (0.0, y.end)],
                BLACK.stroke_width(1),
            )))
            .map_err(err)?;
        for (k, (name, episodes)) in self.runs.iter().enumerate() {
            let colour = RUN_COLOURS[k % RUN_COLOURS.len()];
            chart
                .draw_series(episodes.iter().map(|e| {
                    let style = match (e.censored, e.stability) {
                        // Only part of it was seen: hollow and grey.
                        (true, _) => CENSORED_COLOUR.stroke_width(2),
                        (false, Stability::Unstable) => colour.filled(),
                        (false, Stability::Stable) => colour.stroke_width(2),
                    };
                    Circle::new((e.sigma_per_s, e.omega_rad_s()), DOT_PX, style)
                }))
                .map_err(err)?
                .label(name.as_str())
                .legend(move |(px, py)| Circle::new((px + 8, py), DOT_PX, colour.filled()));
        }
        chart
            .configure_series_labels()
            .label_font((FONT, 14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperLeft)
            .draw()
            .map_err(err)?;
        Ok(())
    }
}
