//! A spectrogram of the steering angle for the ride view: short-time
//! spectra (Hann window, 2.56 s) on a time grid, drawn as a PNG whose
//! columns are times and rows frequencies, as Flight Review's vibration
//! plots. Wobble shows as a bright line in the detector's band, the
//! wheel's imbalance as lines that follow the speed.

use std::f64::consts::TAU;

use serde::Serialize;

/// Window length, s.
const WINDOW_S: f64 = 2.56;
/// Columns at most: a few per pixel of a wide screen.
const MAX_COLUMNS: usize = 1200;
/// Dynamic range shown, dB below the loudest cell.
const RANGE_DB: f64 = 60.0;

/// The picture and where it lies on the axes.
#[derive(Clone, Debug, Serialize)]
pub struct Spectrogram {
    /// Time of the first column's centre, s since boot.
    pub t0_s: f64,
    /// Time of the last column's centre.
    pub t1_s: f64,
    /// Frequency of the top row, Hz (half the frame rate).
    pub f_max_hz: f64,
    /// The PNG, base64.
    pub png_base64: String,
    /// Columns (times) and rows (frequencies).
    pub size: (usize, usize),
}

/// The spectrogram of `steer_deg` at times `t_s` (strictly increasing,
/// `fs_hz` apart except at gaps); `None` when the run is shorter than a
/// window. A column whose window spans a gap is left blank.
#[must_use]
pub fn steer_spectrogram(t_s: &[f64], steer_deg: &[f64], fs_hz: f64) -> Option<Spectrogram> {
    let n = (WINDOW_S * fs_hz).round() as usize;
    if n < 16 || t_s.len() < n || !fs_hz.is_finite() {
        return None;
    }
    let (first, last) = (t_s[0] + 0.5 * WINDOW_S, t_s[t_s.len() - 1] - 0.5 * WINDOW_S);
    let columns = (((last - first) * fs_hz / (n as f64 / 4.0)) as usize + 1).clamp(1, MAX_COLUMNS);
    let step_s = if columns > 1 {
        (last - first) / (columns - 1) as f64
    } else {
        0.0
    };
    let bins = n / 2 + 1;
    let hann: Vec<f64> = (0..n)
        .map(|i| 0.5 - 0.5 * (TAU * i as f64 / n as f64).cos())
        .collect();
    let (cos, sin): (Vec<f64>, Vec<f64>) = (0..n)
        .map(|i| {
            let a = TAU * i as f64 / n as f64;
            (a.cos(), a.sin())
        })
        .unzip();
    let period_s = 1.0 / fs_hz;
    let mut cells: Vec<Option<Vec<f64>>> = Vec::with_capacity(columns);
    let mut window = vec![0.0; n];
    for c in 0..columns {
        let centre = first + c as f64 * step_s;
        let start = t_s.partition_point(|&t| t < centre - 0.5 * WINDOW_S);
        let whole = start + n <= t_s.len()
            && (t_s[start + n - 1] - t_s[start] - (n - 1) as f64 * period_s).abs() < 0.5 * period_s;
        if !whole {
            cells.push(None);
            continue;
        }
        let frames = &steer_deg[start..start + n];
        let mean = frames.iter().sum::<f64>() / n as f64;
        for ((w, &x), &h) in window.iter_mut().zip(frames).zip(&hann) {
            *w = (x - mean) * h;
        }
        // A direct DFT: bins times window length per column is small next
        // to reading the log, and it needs no FFT crate.
        let power: Vec<f64> = (0..bins)
            .map(|k| {
                let (mut re, mut im) = (0.0, 0.0);
                for (i, &w) in window.iter().enumerate() {
                    let at = (k * i) % n;
                    re += w * cos[at];
                    im -= w * sin[at];
                }
                10.0 * (re * re + im * im + 1e-12).log10()
            })
            .collect();
        cells.push(Some(power));
    }
    let top = cells
        .iter()
        .flatten()
        .flatten()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    let mut pixels = vec![0u8; columns * bins * 3];
    for (c, column) in cells.iter().enumerate() {
        for row in 0..bins {
            let bin = bins - 1 - row;
            let rgb = column.as_ref().map_or([0xee, 0xee, 0xee], |p| {
                colour((p[bin] - top + RANGE_DB) / RANGE_DB)
            });
            let at = 3 * (row * columns + c);
            pixels[at..at + 3].copy_from_slice(&rgb);
        }
    }
    let size = (columns, bins);
    let png = crate::plot::encode_png(&pixels, (columns as u32, bins as u32)).ok()?;
    use base64::Engine as _;
    Some(Spectrogram {
        t0_s: first,
        t1_s: first + step_s * (columns - 1) as f64,
        f_max_hz: 0.5 * fs_hz,
        png_base64: base64::engine::general_purpose::STANDARD.encode(png),
        size,
    })
}

/// A dark-to-bright colour scale for `x` in 0..1 (clamped): dark blue,
/// purple, orange, pale yellow.
fn colour(x: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 5] = [
        [13.0, 8.0, 135.0],
        [84.0, 2.0, 163.0],
        [185.0, 50.0, 137.0],
        [249.0, 142.0, 9.0],
        [252.0, 255.0, 164.0],
    ];
    let x = if x.is_finite() {
        x.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let at = x * (STOPS.len() - 1) as f64;
    let i = (at.floor() as usize).min(STOPS.len() - 2);
    let f = at - i as f64;
    std::array::from_fn(|c| (STOPS[i][c] + f * (STOPS[i + 1][c] - STOPS[i][c])).round() as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The brightest row of the middle column: a 6.5 Hz sine is there.
    #[test]
    fn a_sine_is_brightest_at_its_frequency() {
        let fs = 100.0;
        let t: Vec<f64> = (0..3000).map(|i| i as f64 / fs).collect();
        let y: Vec<f64> = t.iter().map(|t| (TAU * 6.5 * t).sin()).collect();
        let s = steer_spectrogram(&t, &y, fs).unwrap();
        let (columns, bins) = s.size;
        use base64::Engine as _;
        let png = base64::engine::general_purpose::STANDARD
            .decode(&s.png_base64)
            .unwrap();
        let decoder = png::Decoder::new(std::io::Cursor::new(png));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        reader.next_frame(&mut buf).unwrap();
        let c = columns / 2;
        let brightness = |row: usize| {
            let at = 3 * (row * columns + c);
            u32::from(buf[at]) + u32::from(buf[at + 1]) + u32::from(buf[at + 2])
        };
        let row = (0..bins).max_by_key(|&r| brightness(r)).unwrap();
        let f = (bins - 1 - row) as f64 * s.f_max_hz / (bins - 1) as f64;
        assert!((f - 6.5).abs() < 0.5, "brightest at {f} Hz");
    }

    #[test]
    fn a_run_shorter_than_a_window_has_none() {
        let t: Vec<f64> = (0..100).map(|i| f64::from(i) / 100.0).collect();
        assert!(steer_spectrogram(&t, &t, 100.0).is_none());
    }
}
