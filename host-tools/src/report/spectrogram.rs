//! A spectrogram of the steering angle for the ride view: short-time
//! spectra (Hann window, 2.56 s) on a time grid, drawn as a PNG whose
//! columns are times and rows frequencies, as Flight Review's vibration
//! plots. Wobble shows as a bright line in the detector's band, the
//! wheel's imbalance as lines that follow the speed.
//!
//! Built as the frames go by ([`SpectrogramBuilder`]): the grid of column
//! times is fixed at the first frame from the run's span, and the builder
//! holds only the last window of frames and the columns' spectra, however
//! long the run.

use std::collections::VecDeque;
use std::f64::consts::TAU;

use serde::Serialize;

/// Window length, s.
const WINDOW_S: f64 = 2.56;
/// Columns at most: a few per pixel of a wide screen.
pub const MAX_COLUMNS: usize = 1200;
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

/// The spectrogram of `steer_deg` at times `t_s` (in file order; a frame
/// not after every earlier one is left out), frames `fs_hz` apart except
/// at gaps; `None` when the run is shorter than a window. A column whose
/// window spans a gap is left blank.
#[must_use]
pub fn steer_spectrogram(t_s: &[f64], steer_deg: &[f64], fs_hz: f64) -> Option<Spectrogram> {
    let latest = t_s.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mut builder = SpectrogramBuilder::new(fs_hz, latest)?;
    for (&t, &s) in t_s.iter().zip(steer_deg) {
        builder.push(t, s);
    }
    builder.finish()
}

/// Where the columns lie: fixed at the first frame.
struct Grid {
    /// Centre of the first column, s.
    first_s: f64,
    /// Between column centres, s.
    step_s: f64,
    columns: usize,
}

/// Builds a [`Spectrogram`] frame by frame, holding one window of frames
/// and at most [`MAX_COLUMNS`] spectra.
pub struct SpectrogramBuilder {
    fs_hz: f64,
    period_s: f64,
    /// Frames per window.
    n: usize,
    /// Time of the latest frame of the run, s.
    latest_s: f64,
    grid: Option<Grid>,
    /// The last `n` frames taken: time and steering angle.
    window: VecDeque<(f64, f64)>,
    /// Frames taken (those after every earlier one).
    frames: usize,
    /// Time of the last frame taken.
    last_s: f64,
    /// The first column whose window's first frame has not come yet.
    next_column: usize,
    /// Columns whose first frame has come (its index), waiting for the
    /// rest of their window.
    waiting: VecDeque<(usize, usize)>,
    /// Each column's power per bin, dB (`None`: blank).
    cells: Vec<Option<Vec<f64>>>,
    hann: Vec<f64>,
    cos: Vec<f64>,
    sin: Vec<f64>,
    scratch: Vec<f64>,
}

impl SpectrogramBuilder {
    /// A builder for frames nominally `fs_hz` apart, the latest of which
    /// is at `latest_s`; `None` when no window fits the rate.
    #[must_use]
    pub fn new(fs_hz: f64, latest_s: f64) -> Option<Self> {
        let n = (WINDOW_S * fs_hz).round() as usize;
        if n < 16 || !fs_hz.is_finite() {
            return None;
        }
        let hann: Vec<f64> = (0..n)
            .map(|i| 0.5 - 0.5 * (TAU * i as f64 / n as f64).cos())
            .collect();
        let (cos, sin): (Vec<f64>, Vec<f64>) = (0..n)
            .map(|i| {
                let a = TAU * i as f64 / n as f64;
                (a.cos(), a.sin())
            })
            .unzip();
        Some(Self {
            fs_hz,
            period_s: 1.0 / fs_hz,
            n,
            latest_s,
            grid: None,
            window: VecDeque::with_capacity(n),
            frames: 0,
            last_s: f64::NEG_INFINITY,
            next_column: 0,
            waiting: VecDeque::new(),
            cells: Vec::new(),
            hann,
            cos,
            sin,
            scratch: vec![0.0; n],
        })
    }

    /// Takes the next frame in file order; one not after every earlier
    /// frame is left out.
    pub fn push(&mut self, t_s: f64, steer_deg: f64) {
        if t_s <= self.last_s {
            return;
        }
        self.last_s = t_s;
        let n = self.n;
        let grid = self.grid.get_or_insert_with(|| {
            let (first, last) = (t_s + 0.5 * WINDOW_S, self.latest_s - 0.5 * WINDOW_S);
            let columns = (((last - first) * self.fs_hz / (n as f64 / 4.0)) as usize + 1)
                .clamp(1, MAX_COLUMNS);
            let step_s = if columns > 1 {
                (last - first) / (columns - 1) as f64
            } else {
                0.0
            };
            Grid {
                first_s: first,
                step_s,
                columns,
            }
        });
        let index = self.frames;
        self.frames += 1;
        if self.window.len() == n {
            self.window.pop_front();
        }
        self.window.push_back((t_s, steer_deg));
        // A column's window starts at its first frame not before its
        // centre less half a window.
        while self.next_column < grid.columns {
            let centre = grid.first_s + self.next_column as f64 * grid.step_s;
            if t_s < centre - 0.5 * WINDOW_S {
                break;
            }
            self.waiting.push_back((self.next_column, index));
            self.next_column += 1;
        }
        while let Some(&(column, start)) = self.waiting.front() {
            if start + n - 1 != index {
                break;
            }
            self.waiting.pop_front();
            let power = self.column();
            self.set(column, power);
        }
    }

    fn set(&mut self, column: usize, power: Option<Vec<f64>>) {
        if self.cells.len() <= column {
            self.cells.resize(column + 1, None);
        }
        self.cells[column] = power;
    }

    /// The spectrum of the window held (`n` frames), or `None` when it
    /// spans a gap.
    fn column(&mut self) -> Option<Vec<f64>> {
        let n = self.n;
        let (t_first, t_last) = (self.window[0].0, self.window[n - 1].0);
        let whole = (t_last - t_first - (n - 1) as f64 * self.period_s).abs() < 0.5 * self.period_s;
        if !whole {
            return None;
        }
        let mean = self.window.iter().map(|f| f.1).sum::<f64>() / n as f64;
        for ((w, f), &h) in self.scratch.iter_mut().zip(&self.window).zip(&self.hann) {
            *w = (f.1 - mean) * h;
        }
        let bins = n / 2 + 1;
        let power = if n.is_power_of_two() {
            let (re, im) = fft(&self.scratch, &self.cos, &self.sin);
            (0..bins)
                .map(|k| 10.0 * (re[k] * re[k] + im[k] * im[k] + 1e-12).log10())
                .collect()
        } else {
            // A direct DFT at rates whose window is not a power of two.
            (0..bins)
                .map(|k| {
                    let (mut re, mut im) = (0.0, 0.0);
                    // `at` runs through k * i modulo n.
                    let mut at = 0;
                    for &w in &self.scratch {
                        re += w * self.cos[at];
                        im -= w * self.sin[at];
                        at += k;
                        if at >= n {
                            at -= n;
                        }
                    }
                    10.0 * (re * re + im * im + 1e-12).log10()
                })
                .collect()
        };
        Some(power)
    }

    /// The spectrogram; `None` when fewer frames than a window came.
    #[must_use]
    pub fn finish(mut self) -> Option<Spectrogram> {
        let grid = self.grid.take()?;
        if self.frames < self.n {
            return None;
        }
        let (columns, bins) = (grid.columns, self.n / 2 + 1);
        // Columns whose window never filled are blank.
        self.cells.resize(columns, None);
        let top = self
            .cells
            .iter()
            .flatten()
            .flatten()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        let mut pixels = vec![0u8; columns * bins * 3];
        for (c, column) in self.cells.iter().enumerate() {
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
            t0_s: grid.first_s,
            t1_s: grid.first_s + grid.step_s * (columns - 1) as f64,
            f_max_hz: 0.5 * self.fs_hz,
            png_base64: base64::engine::general_purpose::STANDARD.encode(png),
            size,
        })
    }
}

/// The discrete Fourier transform of `x` (a power of two long), real and
/// imaginary parts, by an iterative radix-2 FFT; `cos` and `sin` hold the
/// angles `TAU * i / n`. A few thousand operations a window where the
/// direct sum takes some sixty thousand, and no FFT crate.
fn fft(x: &[f64], cos: &[f64], sin: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let n = x.len();
    let bits = n.trailing_zeros();
    let mut re = vec![0.0; n];
    let mut im = vec![0.0; n];
    for (i, &v) in x.iter().enumerate() {
        let j = if bits == 0 {
            0
        } else {
            i.reverse_bits() >> (usize::BITS - bits)
        };
        re[j] = v;
    }
    let mut len = 2;
    while len <= n {
        let (half, step) = (len / 2, n / len);
        for start in (0..n).step_by(len) {
            for j in 0..half {
                let (wr, wi) = (cos[j * step], -sin[j * step]);
                let (a, b) = (start + j, start + j + half);
                let vr = re[b] * wr - im[b] * wi;
                let vi = re[b] * wi + im[b] * wr;
                re[b] = re[a] - vr;
                im[b] = im[a] - vi;
                re[a] += vr;
                im[a] += vi;
            }
        }
        len *= 2;
    }
    (re, im)
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

    /// The spectra of the windows found by searching the whole run for
    /// each column's first frame, as the spectrogram was made before it
    /// was built frame by frame.
    fn searched(t_s: &[f64], steer_deg: &[f64], fs_hz: f64) -> Vec<Option<Vec<f64>>> {
        let n = (WINDOW_S * fs_hz).round() as usize;
        let (first, last) = (t_s[0] + 0.5 * WINDOW_S, t_s[t_s.len() - 1] - 0.5 * WINDOW_S);
        let columns =
            (((last - first) * fs_hz / (n as f64 / 4.0)) as usize + 1).clamp(1, MAX_COLUMNS);
        let step_s = (last - first) / (columns - 1) as f64;
        let period_s = 1.0 / fs_hz;
        let mut b = SpectrogramBuilder::new(fs_hz, t_s[t_s.len() - 1]).unwrap();
        (0..columns)
            .map(|c| {
                let centre = first + c as f64 * step_s;
                let start = t_s.partition_point(|&t| t < centre - 0.5 * WINDOW_S);
                let whole = start + n <= t_s.len()
                    && (t_s[start + n - 1] - t_s[start] - (n - 1) as f64 * period_s).abs()
                        < 0.5 * period_s;
                if !whole {
                    return None;
                }
                b.window = t_s[start..start + n]
                    .iter()
                    .copied()
                    .zip(steer_deg[start..start + n].iter().copied())
                    .collect();
                b.column()
            })
            .collect()
    }

    #[test]
    fn frame_by_frame_the_columns_are_those_of_the_whole_run() {
        let fs = 100.0;
        // 20 min with a 7 s gap and a stretch whose clock went back 3 s
        // (left out), a tone sweeping through the band.
        let mut t: Vec<f64> = Vec::new();
        for i in 0..120_000 {
            let mut s = f64::from(i) / fs;
            if i >= 40_000 {
                s += 7.0;
            }
            if (80_000..80_500).contains(&i) {
                s -= 3.0;
            }
            t.push(s);
        }
        let y: Vec<f64> = t
            .iter()
            .map(|&s| (TAU * (4.0 + s / 300.0) * s).sin() + 0.01 * s)
            .collect();
        let ordered: (Vec<f64>, Vec<f64>) = {
            let mut last = f64::NEG_INFINITY;
            t.iter()
                .zip(&y)
                .filter(|(&s, _)| {
                    let later = s > last;
                    last = last.max(s);
                    later
                })
                .map(|(&s, &v)| (s, v))
                .unzip()
        };
        let expected = searched(&ordered.0, &ordered.1, fs);
        let mut b = SpectrogramBuilder::new(fs, t[t.len() - 1]).unwrap();
        for (&s, &v) in t.iter().zip(&y) {
            b.push(s, v);
        }
        b.cells.resize(expected.len(), None);
        assert_eq!(b.cells.len(), MAX_COLUMNS);
        let blank = expected.iter().filter(|c| c.is_none()).count();
        assert!(blank > 3 && blank < 20, "{blank} blank columns");
        assert_eq!(b.cells, expected);
    }

    #[test]
    fn the_builder_holds_one_window_and_the_columns_whatever_the_run() {
        let fs = 100.0;
        let frames = 2_000_000;
        let mut b = SpectrogramBuilder::new(fs, f64::from(frames - 1) / fs).unwrap();
        let mut most_waiting = 0;
        for i in 0..frames {
            let t = f64::from(i) / fs;
            b.push(t, (TAU * 6.4 * t).sin());
            assert!(b.window.len() <= b.n);
            most_waiting = most_waiting.max(b.waiting.len());
        }
        assert!(most_waiting <= 2, "{most_waiting} columns waiting");
        assert_eq!(b.cells.len(), MAX_COLUMNS);
        assert_eq!(b.finish().unwrap().size, (MAX_COLUMNS, 129));
    }

    #[test]
    fn the_fft_is_the_direct_sum() {
        let n = 256;
        let x: Vec<f64> = (0..n)
            .map(|i| (0.37 * f64::from(i)).sin() + 0.1 * f64::from(i % 7))
            .collect();
        let angle = |i: usize| TAU * i as f64 / n as f64;
        let cos: Vec<f64> = (0..n as usize).map(|i| angle(i).cos()).collect();
        let sin: Vec<f64> = (0..n as usize).map(|i| angle(i).sin()).collect();
        let (re, im) = fft(&x, &cos, &sin);
        for k in 0..n as usize {
            let (mut r, mut m) = (0.0, 0.0);
            for (i, &v) in x.iter().enumerate() {
                r += v * angle(k * i).cos();
                m -= v * angle(k * i).sin();
            }
            assert!(
                (re[k] - r).abs() < 1e-9 && (im[k] - m).abs() < 1e-9,
                "bin {k}"
            );
        }
    }

    #[test]
    fn a_run_shorter_than_a_window_has_none() {
        let t: Vec<f64> = (0..100).map(|i| f64::from(i) / 100.0).collect();
        assert!(steer_spectrogram(&t, &t, 100.0).is_none());
    }
}
