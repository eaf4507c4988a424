//! The QEMU harness: builds the firmware image for `netduinoplus2`, runs it
//! under `qemu-system-arm -icount shift=3,sleep=off` on fixtures with a
//! fresh FAT32 card image, and reads back what it wrote.
//!
//! ```text
//! corpus ride + NMEA capture ─> fixture ─> ride.bin, gps.bin ─┐
//! Scenario (faults) ─────────────────────> scenario.txt ──────┼─> run ─> QEMU ─> card.img ─> decode (wobblog)
//! mkfs.fat ─────────────────────────────> card.img ───────────┘           └──> report lines (ALERT, END...)
//! ```

pub mod card;
pub mod decode;
pub mod fixture;
pub mod run;

pub use run::{image, run, DetectorBench, Outcome, Scenario, Setup, ICOUNT_SHIFT};

use std::path::{Path, PathBuf};

use fixture::{CorpusRide, GpsChunk};

/// The bundled ride: the corpus fixture like the seed paper's Figure 6.
pub const RIDE: &str = "wobble_fig6";
/// The bundled GPS capture: a Quectel L76K at 5 Hz, 30 s (gpsd's test log).
pub const GPS_CAPTURE: &str = "quectel-l76k-nmea.log";
/// When the first GPS byte arrives, µs since boot.
pub const GPS_START_US: u64 = 500_000;

/// A ride's sensor rows, ground truth and GPS bytes.
#[derive(Clone, Debug)]
pub struct Bundle {
    /// The corpus ride.
    pub ride: CorpusRide,
    /// The capture's bytes, scheduled.
    pub gps: Vec<GpsChunk>,
}

/// The bundled ride and capture, for `frames` frames.
///
/// # Errors
/// A fixture is missing.
pub fn bundle(frames: u32) -> Result<Bundle, String> {
    let end_us = u64::from(frames) * fixture::FRAME_US;
    Ok(Bundle {
        ride: fixture::corpus_ride(RIDE)?,
        gps: fixture::gps_schedule(GPS_CAPTURE, GPS_START_US, end_us)?,
    })
}

impl Bundle {
    /// Checks alert-ons (time µs, reported frequency Hz) against the ride's
    /// ground truth and the detector's goals: exactly one per episode that
    /// expects one, none elsewhere, each within
    /// [`goals::WORST_LATENCY_S`](crate::metrics::goals::WORST_LATENCY_S) of
    /// the envelope reaching 0.5 deg (and not more than 0.5 s before it)
    /// and within [`goals::FREQ_ERROR_HZ`](crate::metrics::goals::FREQ_ERROR_HZ)
    /// of the true frequency.
    ///
    /// # Errors
    /// What is wrong, for the test's message.
    pub fn check_alerts(&self, ons: &[(u64, f64)]) -> Result<(), String> {
        use crate::metrics::goals;
        let episodes: Vec<_> = self
            .ride
            .truth
            .episodes
            .iter()
            .filter(|e| e.alert_expected)
            .collect();
        if ons.len() != episodes.len() {
            return Err(format!(
                "{} alerts for {} episodes: {ons:?}",
                ons.len(),
                episodes.len()
            ));
        }
        for (&(t_us, freq_hz), e) in ons.iter().zip(&episodes) {
            let latency_s = t_us as f64 / 1e6 - e.t_ref_s;
            let freq_error_hz = (freq_hz - e.freq_hz).abs();
            if !(-0.5..=goals::WORST_LATENCY_S).contains(&latency_s)
                || freq_error_hz > goals::FREQ_ERROR_HZ
            {
                return Err(format!(
                    "alert at {t_us} µs, {freq_hz} Hz: latency {latency_s:.2} s, frequency error \
                     {freq_error_hz:.2} Hz for the episode at {} Hz reaching 0.5 deg at {} s",
                    e.freq_hz, e.t_ref_s
                ));
            }
        }
        Ok(())
    }

    /// A setup for running this bundle with `scenario` in `dir`.
    #[must_use]
    pub fn setup(&self, dir: PathBuf, scenario: Scenario) -> Setup<'_> {
        Setup {
            dir,
            scenario,
            rows: &self.ride.rows,
            gps: &self.gps,
            config: None,
        }
    }
}

/// What `fsck.fat -n` may report after a power cut while the log file was
/// open, all of it space accounting, none of it data written before the
/// last flush:
/// - the file's directory entry holds the size of the last flush while its
///   cluster chain already reaches further (fsck would truncate the chain);
/// - the free-cluster count in the FS info sector is behind;
/// - a cluster allocation was cut between its writes: the second FAT copy
///   lags the first, or a new cluster is marked used but not yet linked
///   from the directory entry (fsck would reclaim it).
pub const UNCLOSED_FILE_FSCK: [&str; 8] = [
    "/RUN",
    "File size is ",
    "Truncating file to ",
    "Free cluster summary wrong",
    "Auto-correcting.",
    "FATs differ but appear to be intact.",
    "Using first FAT.",
    "Reclaimed ",
];

/// Whether an `fsck.fat` complaint is one of [`UNCLOSED_FILE_FSCK`].
#[must_use]
pub fn is_unclosed_file_state(problem: &str) -> bool {
    UNCLOSED_FILE_FSCK.iter().any(|p| problem.starts_with(p))
}

/// A fresh working directory for run `name` under `base`.
///
/// # Errors
/// It cannot be created.
pub fn work_dir(base: &Path, name: &str) -> Result<PathBuf, String> {
    let dir = base.join("qemu-runs").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    Ok(dir)
}
