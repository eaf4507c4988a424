use wobble_core::config::Config;
use wobble_core::detector::{AlertEvent, DetectorConfig};

const TAU: f32 = core::f32::consts::TAU;

fn first_on(cfg: DetectorConfig, speed: Option<f32>, secs: f32, sig: &dyn Fn(usize, f32) -> f32) -> Option<(f32, f32, f32)> {
    let mut d = wobble_core::detector::Detector::new(cfg, 2.18).unwrap();
    for i in 0..(secs * 100.0) as usize {
        let t = i as f32 / 100.0;
        if let Some(AlertEvent::On { freq_hz, amp_deg }) = d.push(sig(i, t), speed) {
            return Some((t, freq_hz, amp_deg));
        }
    }
    None
}

fn main() {
    let long = Config::default().detector;
    let short = DetectorConfig { freq_window_s: long.window_s, ..long };
    let uniform = |i: u32| { let x = i.wrapping_mul(1_103_515_245).wrapping_add(12_345); (x >> 8) as f32 / (1u32 << 24) as f32 - 0.5 };
    let rms_deg: f32 = std::env::args().nth(1).map_or(0.1, |a| a.parse().unwrap());
    let speed: Option<f32> = std::env::args().nth(2).map(|a| a.parse().unwrap());
    for (name, cfg) in [("long", long), ("short", short)] {
        let mut errs = Vec::new();
        for case in 0..36u32 {
            let f = 6.0 + 3.0 * (case % 12) as f32 / 11.0;
            let growth = 1.0 + (case / 12) as f32;
            let phase = case as f32 * 0.7;
            let sig = move |i: usize, t: f32| {
                let env = (0.02 * (growth * (t - 3.0)).exp()).min(3.0);
                env * (TAU * f * t + phase).sin() + uniform(i as u32 + case * 100_000) * rms_deg * 12f32.sqrt()
            };
            match first_on(cfg, speed, 10.0, &sig) { Some((_, fr, _)) => errs.push((fr - f).abs()), None => println!("missed {case}") }
        }
        let rms = (errs.iter().map(|e| e * e).sum::<f32>() / errs.len() as f32).sqrt();
        let worst = errs.iter().cloned().fold(0.0, f32::max);
        println!("{name}: n {} rms {rms:.4} worst {worst:.3}", errs.len());
    }
}
