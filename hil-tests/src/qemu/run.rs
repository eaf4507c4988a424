//! Building the QEMU image once and running it on a scenario.

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use wobble_core::config::Config;

use super::card;
use super::fixture::{self, GpsChunk};
use crate::corpus::Row;

/// The MCU target of the image.
pub const TARGET: &str = "thumbv7em-none-eabihf";
/// A run taking longer than this on the wall clock has hung.
pub const WALL_LIMIT: Duration = Duration::from_secs(180);
/// QEMU's instruction clock: each instruction takes 2^shift ns of virtual
/// time, so 8 ns (125 MIPS, about the F405's 168 MHz at a little over one
/// cycle per instruction). Virtual µs × 1000 / 8 counts instructions.
pub const ICOUNT_SHIFT: u32 = 3;

/// Builds the image (once per process; a no-op when it is up to date) and
/// returns its path.
///
/// # Errors
/// The build failed (missing target: `rustup target add thumbv7em-none-eabihf`).
pub fn image() -> Result<PathBuf, String> {
    static IMAGE: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    IMAGE.get_or_init(build_image).clone()
}

fn build_image() -> Result<PathBuf, String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    // From the image's own directory, so its `.cargo/config.toml` gives it
    // the board's size-optimised release profile.
    let status = Command::new(cargo)
        .current_dir(root.join("hil-tests/qemu-image"))
        .args(["build", "--release", "--target", TARGET])
        .status()
        .map_err(|e| format!("cargo: {e}"))?;
    if !status.success() {
        return Err("building the QEMU image failed".into());
    }
    let target_dir =
        std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| root.join("target"), PathBuf::from);
    Ok(target_dir
        .join(TARGET)
        .join("release")
        .join("wobble-qemu-image"))
}

/// What the harness asks of a run (`scenario.txt`, see the image's
/// `scenario.rs`).
#[derive(Clone, Debug, Default)]
pub struct Scenario {
    /// Ride length, frames.
    pub frames: u32,
    /// (block write number, stall ms).
    pub stalls: Vec<(u32, u32)>,
    /// Power cut before this block write.
    pub cut_at_write: Option<u32>,
    /// Power cut inside a block write: (write number, thousandths of its
    /// transfer and busy time).
    pub cut_in_write: Option<(u32, u32)>,
    /// Seed of the card's timing (the image's default when `None`).
    pub card_seed: Option<u32>,
    /// Card absent from/to, ms.
    pub card_absent_ms: Option<(u32, u32)>,
    /// IMU dead from, ms.
    pub imu_dead_from_ms: Option<u32>,
    /// IMU data registers frozen from/to, ms.
    pub imu_stuck_ms: Option<(u32, u32)>,
    /// Steering potentiometer's wiper open from/to, ms.
    pub steer_open_ms: Option<(u32, u32)>,
    /// GPS noise from/to, ms.
    pub gps_garbage_ms: Option<(u32, u32)>,
    /// Instead of riding, time the wobble detector and the margin warning
    /// over the ride's steering and wheel speed and report it in a `BENCH`
    /// line ([`Outcome::detector_bench`]).
    pub bench_detector: bool,
}

impl Scenario {
    /// A plain ride of `frames` frames.
    #[must_use]
    pub fn ride(frames: u32) -> Self {
        Self {
            frames,
            ..Self::default()
        }
    }

    fn text(&self) -> String {
        let mut s = format!("frames={}\n", self.frames);
        for (w, ms) in &self.stalls {
            s += &format!("stall={w}:{ms}\n");
        }
        if let Some(w) = self.cut_at_write {
            s += &format!("cut={w}\n");
        }
        if let Some((w, permille)) = self.cut_in_write {
            s += &format!("cut_in_write={w}:{permille}\n");
        }
        if let Some(seed) = self.card_seed {
            s += &format!("card_seed={seed}\n");
        }
        if let Some((a, b)) = self.card_absent_ms {
            s += &format!("card_absent_ms={a}:{b}\n");
        }
        if let Some(t) = self.imu_dead_from_ms {
            s += &format!("imu_dead_ms={t}\n");
        }
        for (key, window) in [
            ("imu_stuck_ms", self.imu_stuck_ms),
            ("steer_open_ms", self.steer_open_ms),
            ("gps_garbage_ms", self.gps_garbage_ms),
        ] {
            if let Some((a, b)) = window {
                s += &format!("{key}={a}:{b}\n");
            }
        }
        if self.bench_detector {
            s += "bench=detector\n";
        }
        s
    }
}

/// The inputs of a run.
pub struct Setup<'a> {
    /// Working directory (created; holds the card image afterwards).
    pub dir: PathBuf,
    /// The scenario.
    pub scenario: Scenario,
    /// Sensor rows to replay.
    pub rows: &'a [Row],
    /// GPS bytes to replay.
    pub gps: &'a [GpsChunk],
    /// `CONFIG.TXT` to put on the card (none: the defaults), which the
    /// image reads as the board does; the sensors are mounted and
    /// calibrated as it says.
    pub config: Option<&'a str>,
}

impl Setup<'_> {
    /// The configuration the image will run with.
    ///
    /// # Errors
    /// The text has faults: a test's configuration must be taken whole.
    pub fn config(&self) -> Result<Config, String> {
        let loaded = Config::parse(self.config.unwrap_or_default().as_bytes());
        if loaded.faults.is_empty() {
            Ok(loaded.config)
        } else {
            Err(format!("CONFIG.TXT has faults: {:?}", loaded.faults))
        }
    }
}

/// How a run went.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// QEMU's exit code (the image's: 0 done, 2 bad scenario, 3 power cut).
    pub code: i32,
    /// Report lines, in order.
    pub lines: Vec<String>,
    /// Wall-clock time of the QEMU process.
    pub wall: Duration,
    /// The card image.
    pub card: PathBuf,
}

impl Outcome {
    /// The `key=value` fields of the first line starting with `kind`.
    #[must_use]
    pub fn fields(&self, kind: &str) -> Option<BTreeMap<String, String>> {
        self.lines
            .iter()
            .find(|l| l.split(' ').next() == Some(kind))
            .map(|l| parse_fields(l))
    }

    /// A numeric field of the first `kind` line.
    #[must_use]
    pub fn number(&self, kind: &str, key: &str) -> Option<u64> {
        self.fields(kind)?.get(key)?.parse().ok()
    }

    /// Index (from 0) of the frame stamped `t_us`: frame k is due at the
    /// sampler's `START` time + (k + 1) x 10 ms.
    #[must_use]
    pub fn frame_index(&self, t_us: u64) -> u64 {
        let start_us = self.number("START", "t_us").unwrap_or(0);
        ((t_us.saturating_sub(start_us) + fixture::FRAME_US / 2) / fixture::FRAME_US)
            .saturating_sub(1)
    }

    /// Alert switchings the image reported as they happened: (on, t_us).
    #[must_use]
    pub fn alerts(&self) -> Vec<(bool, u64)> {
        self.lines
            .iter()
            .filter_map(|l| {
                let rest = l.strip_prefix("ALERT ")?;
                let f = parse_fields(l);
                Some((rest.starts_with("on"), f.get("t_us")?.parse().ok()?))
            })
            .collect()
    }
}

impl Outcome {
    /// The alert-ons reported live: (time µs, frequency Hz).
    #[must_use]
    pub fn alert_ons(&self) -> Vec<(u64, f64)> {
        self.lines
            .iter()
            .filter(|l| l.starts_with("ALERT on "))
            .filter_map(|l| {
                let f = parse_fields(l);
                Some((
                    f.get("t_us")?.parse().ok()?,
                    f.get("freq_hz")?.parse().ok()?,
                ))
            })
            .collect()
    }
}

/// The detector benchmark's figures (the image's `BENCH` line), in
/// instructions on QEMU's fixed instruction clock ([`ICOUNT_SHIFT`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DetectorBench {
    /// Samples timed.
    pub samples: u64,
    /// Mean per sample.
    pub mean: u64,
    /// The worst sample...
    pub worst: u64,
    /// ...and which (from 0).
    pub worst_at: u64,
    /// The worst sample that reported a kick (its ring-down fit and the
    /// margin estimate ran on it).
    pub worst_kick: u64,
    /// The worst margin estimate alone.
    pub worst_margin: u64,
    /// Alert switchings, kicks reported and margin estimates made.
    pub alert_changes: u64,
    /// See `alert_changes`.
    pub kicks: u64,
    /// See `alert_changes`.
    pub estimates: u64,
}

impl DetectorBench {
    /// A 10 ms frame at 168 MHz is 1.68 M cycles: the detector may take at
    /// most 1 % of it on average...
    pub const MEAN_BUDGET: u64 = 16_800;
    /// ...and 10 % on its worst sample (the sampler's tick must leave the
    /// GPS and card tasks their time).
    pub const WORST_BUDGET: u64 = 168_000;
}

impl Outcome {
    /// The detector benchmark's figures, if the run reported them.
    #[must_use]
    pub fn detector_bench(&self) -> Option<DetectorBench> {
        let n = |key| self.number("BENCH", key);
        let instructions = |ns: u64| ns >> ICOUNT_SHIFT;
        let samples = n("samples").filter(|&s| s > 0)?;
        Some(DetectorBench {
            samples,
            mean: instructions(n("ns")?) / samples,
            worst: instructions(n("max_ns")?),
            worst_at: n("max_at")?,
            worst_kick: instructions(n("kick_max_ns")?),
            worst_margin: instructions(n("margin_max_ns")?),
            alert_changes: n("alert_changes")?,
            kicks: n("kicks")?,
            estimates: n("estimates")?,
        })
    }
}

fn parse_fields(line: &str) -> BTreeMap<String, String> {
    line.split(' ')
        .filter_map(|kv| kv.split_once('='))
        .map(|(k, v)| (k.to_owned(), v.to_owned()))
        .collect()
}

/// Runs the image on `setup` with a fresh card (`prepare_card` may alter
/// it first), passing each report line to `on_line` as it comes.
///
/// # Errors
/// The image, QEMU or mkfs.fat is missing, or QEMU ran past [`WALL_LIMIT`].
pub fn run(
    setup: &Setup<'_>,
    prepare_card: impl FnOnce(&Path) -> Result<(), String>,
    mut on_line: impl FnMut(&str),
) -> Result<Outcome, String> {
    let image = image()?;
    let dir = &setup.dir;
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let io = |e: std::io::Error| format!("{}: {e}", dir.display());
    let card = dir.join("card.img");
    card::mkfs(&card)?;
    if let Some(text) = setup.config {
        card::put_file(&card, wobble_core::config::FILE_NAME, text.as_bytes())?;
    }
    prepare_card(&card)?;
    std::fs::write(dir.join("scenario.txt"), setup.scenario.text()).map_err(io)?;
    fixture::write_ride(
        &dir.join("ride.bin"),
        setup.rows,
        setup.scenario.frames as usize,
        &setup.config()?,
    )
    .map_err(io)?;
    fixture::write_gps(&dir.join("gps.bin"), setup.gps).map_err(io)?;

    let started = Instant::now();
    let mut child = Command::new("qemu-system-arm")
        .current_dir(dir)
        .args([
            "-machine",
            "netduinoplus2",
            "-nographic",
            "-monitor",
            "none",
            "-serial",
            "null",
        ])
        .args(["-semihosting-config", "enable=on,target=native"])
        // A fixed instruction clock instead of `shift=auto`: auto scales virtual time to the
        // host's speed, so on a loaded machine the emulated CPU slowed to a
        // crawl, the detector's 50 ms hop made ticks 4 ms late and the
        // timing assertions failed at random. A fixed shift makes a run's
        // virtual time a function of the instructions alone; `sleep=off`
        // still skips idle time.
        .args([
            "-icount",
            &format!("shift={ICOUNT_SHIFT},sleep=off"),
            "-kernel",
        ])
        .arg(&image)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| format!("qemu-system-arm: {e} (install qemu-system-arm)"))?;
    let pid = child.id();
    // A watchdog for a hung emulator: the only wall-clock limit in the harness.
    let (done_tx, done_rx) = std::sync::mpsc::channel::<()>();
    let watchdog = std::thread::spawn(move || {
        if done_rx.recv_timeout(WALL_LIMIT).is_err() {
            let _ = Command::new("kill").arg(pid.to_string()).status();
            return true;
        }
        false
    });
    let mut lines = Vec::new();
    if let Some(stdout) = child.stdout.take() {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            on_line(&line);
            lines.push(line);
        }
    }
    let status = child.wait().map_err(|e| format!("qemu: {e}"))?;
    let _ = done_tx.send(());
    if watchdog.join().unwrap_or(false) {
        return Err(format!(
            "QEMU ran longer than {WALL_LIMIT:?}; last lines: {:?}",
            lines.iter().rev().take(5).collect::<Vec<_>>()
        ));
    }
    Ok(Outcome {
        code: status.code().unwrap_or(-1),
        lines,
        wall: started.elapsed(),
        card,
    })
}
