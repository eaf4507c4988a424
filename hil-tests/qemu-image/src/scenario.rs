//! What the test harness asks of one run, read from `scenario.txt` in
//! QEMU's working directory: `key=value` lines, times in ms of virtual time
//! since boot, block writes counted from 1.
//!
//! | key | meaning |
//! |---|---|
//! | `frames=N` | ride length in frames (required) |
//! | `stall=W:MS` | block write number W takes MS ms (up to 16 lines) |
//! | `cut=W` | the power goes just before block write W |
//! | `cut_in_write=W:P` | the power goes P thousandths into block write W's transfer and busy time |
//! | `card_seed=N` | seed of the card's timing (`sd_timing.rs`; default 1) |
//! | `card_absent_ms=A:B` | the card does not answer from A to B ms |
//! | `imu_dead_ms=A` | the IMU stops answering at A ms (every byte reads 0xFF) |
//! | `imu_stuck_ms=A:B` | the IMU's data registers freeze from A to B ms |
//! | `steer_open_ms=A:B` | the potentiometer's wiper is open (ADC at full scale) from A to B ms |
//! | `gps_garbage_ms=A:B` | the GPS sends noise instead of NMEA from A to B ms |
//! | `bench=detector` | no ride: time the wobble detector and the margin warning over the ride's steering and wheel speed |

use heapless::Vec;

/// Most stall lines honoured.
pub const MAX_STALLS: usize = 16;

/// A run's scenario (see the module docs).
#[derive(Debug, Default)]
pub struct Scenario {
    pub frames: u32,
    pub stalls: Vec<(u32, u32), MAX_STALLS>,
    pub cut_at_write: Option<u32>,
    pub cut_in_write: Option<(u32, u32)>,
    pub card_seed: u32,
    pub card_absent_ms: Option<(u32, u32)>,
    pub imu_dead_from_ms: Option<u32>,
    pub imu_stuck_ms: Option<(u32, u32)>,
    pub steer_open_ms: Option<(u32, u32)>,
    pub gps_garbage_ms: Option<(u32, u32)>,
    pub bench_detector: bool,
}

fn pair(v: &str) -> Option<(u32, u32)> {
    let (a, b) = v.split_once(':')?;
    Some((a.parse().ok()?, b.parse().ok()?))
}

impl Scenario {
    /// Parses the file's text; `Err` names the first line it did not
    /// understand, so a harness typo fails the run loudly.
    pub fn parse(text: &str) -> Result<Self, &str> {
        let mut s = Self {
            card_seed: 1,
            ..Self::default()
        };
        for line in text.lines().map(str::trim).filter(|l| !l.is_empty()) {
            let (key, value) = line.split_once('=').ok_or(line)?;
            let ok = match key {
                "frames" => value.parse().map(|n| s.frames = n).is_ok(),
                "stall" => pair(value).is_some_and(|p| s.stalls.push(p).is_ok()),
                "cut" => value.parse().map(|w| s.cut_at_write = Some(w)).is_ok(),
                "cut_in_write" => pair(value).map(|p| s.cut_in_write = Some(p)).is_some(),
                "card_seed" => value.parse().map(|n| s.card_seed = n).is_ok(),
                "card_absent_ms" => pair(value).map(|p| s.card_absent_ms = Some(p)).is_some(),
                "imu_dead_ms" => value.parse().map(|t| s.imu_dead_from_ms = Some(t)).is_ok(),
                "imu_stuck_ms" => pair(value).map(|p| s.imu_stuck_ms = Some(p)).is_some(),
                "steer_open_ms" => pair(value).map(|p| s.steer_open_ms = Some(p)).is_some(),
                "gps_garbage_ms" => pair(value).map(|p| s.gps_garbage_ms = Some(p)).is_some(),
                "bench" => (value == "detector")
                    .then(|| s.bench_detector = true)
                    .is_some(),
                _ => false,
            };
            if !ok {
                return Err(line);
            }
        }
        Ok(s)
    }
}

/// Whether `t_ms` lies in the window `[a, b)`.
pub fn within(window: Option<(u32, u32)>, t_ms: u64) -> bool {
    window.is_some_and(|(a, b)| (u64::from(a)..u64::from(b)).contains(&t_ms))
}
