//! The campaigns' bicycles' true wobble growth rate sigma against speed,
//! from 0.4 to 1.1 of each wobble speed, and its curvature (second
//! difference): how far sigma bends beyond the kicks of a campaign.
//!
//! ```text
//! cargo run -p wobble-hil --release --example wobble_bend
//! ```

use wobble_hil::corpus::signal::FS_HZ;
use wobble_hil::corpus::simulated::bike::Bike;
use wobble_hil::corpus::simulated::campaign::{self, wobble_speed_mps};

fn main() -> Result<(), String> {
    // The campaigns' four bicycles, then those nothing was tuned on.
    let mut variants = campaign::variants()?;
    variants.extend(campaign::unseen_variants()?);
    for v in &variants {
        let mut bike = Bike::from_set(&v.params()?, 1.0 / FS_HZ)?;
        let w = wobble_speed_mps(&mut bike).ok_or("no wobble speed")?;
        println!("{}: wobble speed {w:.3} m/s", v.name);
        let h = 0.05 * w;
        let mut max_bend: f64 = 0.0;
        for i in 8..=22 {
            let u = h * f64::from(i);
            let s = |u: f64, bike: &mut Bike| bike.wobble(u, false).map(|m| m.value.re);
            let (a, b, c) = (s(u - h, &mut bike), s(u, &mut bike), s(u + h, &mut bike));
            if let (Some(a), Some(b), Some(c)) = (a, b, c) {
                let bend = (a - 2.0 * b + c) / (h * h);
                if (0.45..=1.05).contains(&(u / w)) {
                    max_bend = max_bend.max(bend.abs());
                }
                println!(
                    "  u {u:.3} ({:.2} W)  sigma {b:+.4} 1/s  slope {:.4}  bend {bend:+.4} 1/s per (m/s)^2",
                    u / w,
                    (c - a) / (2.0 * h)
                );
            }
        }
        println!("  largest |bend| over 0.45-1.05 W: {max_bend:.4}");
    }
    Ok(())
}
