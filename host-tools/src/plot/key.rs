//! A figure's key, drawn beside its plot rather than over the data: the
//! chart leaves [`width_px`] free on its right and [`draw`] fills it.
//! (plotters' own series labels clip their swatches to the plotting area,
//! so they can only sit on the data.)

use plotters::coord::{CoordTranslate, Shift};
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use super::FONT;

/// Text size of a key, px.
const FONT_PX: u32 = 13;
/// Space between a plot and its key, px.
const GAP_PX: u32 = 12;
/// Width of an entry's swatch, px.
const SWATCH_PX: i32 = 24;
/// Padding inside the key's border, px.
const PADDING_PX: i32 = 6;
/// Space between the key and the figure's edge, px.
const EDGE_PX: u32 = 6;
/// Height of one entry, px.
const LINE_PX: i32 = 18;

/// How an entry shows what it names.
#[derive(Clone, Copy, Debug)]
pub enum Swatch {
    /// A filled box (a shaded span or band).
    Fill(RGBAColor),
    /// A short upright line (a marker across the plot), of this width.
    Upright(RGBColor, u32),
    /// A line along the swatch.
    Line {
        /// Colour.
        colour: RGBColor,
        /// Stroke width, px.
        width: u32,
        /// Dash and gap lengths, px, for a broken line.
        dashes: Option<(u32, u32)>,
    },
    /// A filled dot of this radius.
    Dot(RGBColor, i32),
}

impl Swatch {
    /// A solid line of `width`.
    #[must_use]
    pub fn line(colour: RGBColor, width: u32) -> Self {
        Self::Line {
            colour,
            width,
            dashes: None,
        }
    }

    fn draw<DB: DrawingBackend>(
        self,
        area: &DrawingArea<DB, Shift>,
        (x, y): (i32, i32),
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let end = x + SWATCH_PX;
        match self {
            Self::Fill(colour) => area.draw(&Rectangle::new(
                [(x + 2, y - 6), (end - 2, y + 6)],
                colour.filled(),
            )),
            Self::Upright(colour, width) => {
                let mid = x + SWATCH_PX / 2;
                area.draw(&PathElement::new(
                    vec![(mid, y - 7), (mid, y + 7)],
                    colour.stroke_width(width),
                ))
            }
            Self::Line {
                colour,
                width,
                dashes,
            } => {
                let path = vec![(x, y), (end, y)];
                let style = colour.stroke_width(width);
                match dashes {
                    Some((dash, gap)) => area.draw(&DashedPathElement::new(path, dash, gap, style)),
                    None => area.draw(&PathElement::new(path, style)),
                }
            }
            Self::Dot(colour, r) => {
                area.draw(&Circle::new((x + SWATCH_PX / 2, y), r, colour.filled()))
            }
        }
    }
}

/// The margin a key of `labels` needs beside a plot, px: the gaps, the
/// swatch, the padding and the widest label; 0 for no labels.
///
/// # Errors
/// The font cannot measure the text.
pub fn width_px<DB: DrawingBackend, S: AsRef<str>>(
    area: &DrawingArea<DB, Shift>,
    labels: &[S],
) -> Result<u32, String> {
    let font = TextStyle::from((FONT, FONT_PX).into_font());
    let mut widest = None;
    for label in labels {
        let (w, _) = area
            .estimate_text_size(label.as_ref(), &font)
            .map_err(|e| e.to_string())?;
        widest = widest.max(Some(w));
    }
    Ok(widest.map_or(0, |w| {
        GAP_PX + SWATCH_PX.unsigned_abs() + 3 * PADDING_PX.unsigned_abs() + w + EDGE_PX
    }))
}

/// Draws the key of `entries` (label and swatch, top to bottom) in the
/// right `width_px` of `area` (the [`width_px`] of its labels), level with
/// the top of `plot`, the chart's plotting area.
///
/// # Errors
/// The backend's error, as text.
pub fn draw<DB: DrawingBackend, CT: CoordTranslate>(
    area: &DrawingArea<DB, Shift>,
    plot: &DrawingArea<DB, CT>,
    width_px: u32,
    entries: &[(String, Swatch)],
) -> Result<(), String> {
    if entries.is_empty() {
        return Ok(());
    }
    let top = plot.get_base_pixel().1 - area.get_base_pixel().1;
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let (w, _) = area.dim_in_pixel();
    let left = i32::try_from(w.saturating_sub(width_px) + GAP_PX).map_err(|e| e.to_string())?;
    let right = i32::try_from(w.saturating_sub(EDGE_PX + 1)).map_err(|e| e.to_string())?;
    let rows = i32::try_from(entries.len()).map_err(|e| e.to_string())?;
    let bottom = top + 2 * PADDING_PX + rows * LINE_PX;
    area.draw(&Rectangle::new(
        [(left, top), (right, bottom)],
        WHITE.filled(),
    ))
    .map_err(err)?;
    area.draw(&Rectangle::new(
        [(left, top), (right, bottom)],
        BLACK.mix(0.4).stroke_width(1),
    ))
    .map_err(err)?;
    let font =
        TextStyle::from((FONT, FONT_PX).into_font()).pos(plotters::style::text_anchor::Pos::new(
            plotters::style::text_anchor::HPos::Left,
            plotters::style::text_anchor::VPos::Center,
        ));
    for (k, (label, swatch)) in (0..).zip(entries) {
        let y = top + PADDING_PX + k * LINE_PX + LINE_PX / 2;
        swatch.draw(area, (left + PADDING_PX, y)).map_err(err)?;
        area.draw(&Text::new(
            label.clone(),
            (left + 2 * PADDING_PX + SWATCH_PX, y),
            font.clone(),
        ))
        .map_err(err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The SVG of a 600 x 300 figure whose plot starts 20 px down, with
    /// the key of `entries` beside it, and the key's width.
    fn drawn(entries: &[(String, Swatch)]) -> (String, u32) {
        super::super::register_font();
        let mut svg = String::new();
        let labels: Vec<&str> = entries.iter().map(|e| e.0.as_str()).collect();
        let key_px;
        {
            let root = SVGBackend::with_string(&mut svg, (600, 300)).into_drawing_area();
            key_px = width_px(&root, &labels).unwrap();
            let plot = root.margin(20, 0, 0, 0);
            draw(&root, &plot, key_px, entries).unwrap();
            root.present().unwrap();
        }
        (svg, key_px)
    }

    /// The `name` attribute of the SVG element `el` as a number.
    fn attr(el: &str, name: &str) -> i32 {
        let at = el.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
        el[at..at + el[at..].find('"').unwrap()].parse().unwrap()
    }

    #[test]
    fn a_key_fills_the_width_it_asked_for_level_with_the_plot() {
        let entries = vec![
            ("shaded".to_string(), Swatch::Fill(RED.mix(0.2))),
            ("a much longer label".to_string(), Swatch::line(BLUE, 2)),
            ("marker".to_string(), Swatch::Upright(GREEN, 2)),
            (
                "dashed".to_string(),
                Swatch::Line {
                    colour: BLACK,
                    width: 2,
                    dashes: Some((4, 3)),
                },
            ),
            ("dot".to_string(), Swatch::Dot(BLACK, 4)),
        ];
        let (svg, key_px) = drawn(&entries);
        let (short, _) = drawn(&entries[..1]);
        assert!(key_px > 150 && key_px < 300, "{key_px}");
        assert!(svg.len() > short.len());
        // The frame: from the gap after the plot to the edge's margin,
        // from the plot's top down one line per entry.
        let frame = svg
            .split("<rect")
            .skip(1)
            .find(|e| e.contains("fill=\"none\""))
            .unwrap();
        let left = 600 - i32::try_from(key_px).unwrap() + GAP_PX as i32;
        assert_eq!(attr(frame, "x"), left);
        assert_eq!(attr(frame, "y"), 20);
        assert_eq!(
            attr(frame, "x") + attr(frame, "width"),
            600 - EDGE_PX as i32 - 1
        );
        assert_eq!(attr(frame, "height"), 2 * PADDING_PX + 5 * LINE_PX);
        // Each label after its swatch, one line apart, in order.
        let texts: Vec<&str> = svg.split("<text").skip(1).collect();
        assert_eq!(texts.len(), 5);
        for (k, (t, (label, _))) in texts.iter().zip(&entries).enumerate() {
            assert!(t.contains(label.as_str()), "{t}");
            assert_eq!(attr(t, "x"), left + 2 * PADDING_PX + SWATCH_PX);
            let k = i32::try_from(k).unwrap();
            let y = attr(t, "y");
            let mid = 20 + PADDING_PX + k * LINE_PX + LINE_PX / 2;
            assert!((y - mid).abs() <= LINE_PX / 2, "{label}: y {y}, line {mid}");
        }
        // The shaded swatch: a box inside the swatch's width, on its line.
        let fill = svg
            .split("<rect")
            .skip(1)
            .find(|e| e.contains("fill=\"#FF0000\""))
            .unwrap();
        assert_eq!(attr(fill, "x"), left + PADDING_PX + 2);
        assert_eq!(attr(fill, "width"), SWATCH_PX - 4);
        assert_eq!(attr(fill, "y"), 20 + PADDING_PX + LINE_PX / 2 - 6);
        // The dashed swatch is broken, the solid one whole.
        assert!(svg.matches("stroke=\"#000000\" stroke-width=\"2\"").count() >= 3);
    }

    #[test]
    fn no_entries_no_key_and_no_room() {
        let (svg, key_px) = drawn(&[]);
        assert_eq!(key_px, 0);
        assert!(!svg.contains("<rect"), "{svg}");
        assert!(!svg.contains("<text"), "{svg}");
    }
}
