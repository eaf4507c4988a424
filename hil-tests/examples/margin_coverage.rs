//! The margin regression over many simulated campaigns: from the kicks
//! `campaign_kicks` wrote (one CSV line per true kick), each campaign's
//! prediction and 95 % interval for each trend and each kick source, against
//! the bicycle's true wobble speed; and how the kicks' stated uncertainties
//! compare with their actual errors.
//!
//! ```text
//! SEEDS=100..112 cargo run -p wobble-hil --release --example campaign_kicks > kicks.csv
//! cargo run -p wobble-hil --release --example margin_coverage -- kicks.csv
//! ```
//! `VERBOSE=1` prints every campaign; `BEND=-1:3:0.7` adds a line
//! assuming that bend shape (mean:SD towards convex:SD towards concave, of
//! the dimensionless shape of `wobblog::analysis::margin::bend`).

use std::collections::BTreeMap;

use wobblog::analysis::campaign_kicks::card_sd;
use wobblog::analysis::margin::{predict_bent, BendPrior, KickPoint, Trend};

/// One line of the CSV: the campaign, the truth, and the two measurements.
struct Line {
    campaign: (String, u64),
    wobble_speed_mps: f64,
    true_sigma: f64,
    host: Option<KickPoint>,
    card: Option<KickPoint>,
}

fn parse(text: &str) -> Result<Vec<Line>, String> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().ok_or("empty CSV")?.split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or(format!("no column {name}"))
    };
    let cols: Vec<usize> = [
        "variant",
        "seed",
        "wobble_speed_mps",
        "true_sigma_per_s",
        "host_speed_mps",
        "host_sigma_per_s",
        "host_sd_per_s",
        "host_freq_hz",
        "card_speed_mps",
        "card_sigma_per_s",
        "card_se_per_s",
        "card_freq_hz",
    ]
    .iter()
    .map(|n| col(n))
    .collect::<Result<_, _>>()?;
    lines
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            let num = |i: usize| cells.get(cols[i]).and_then(|c| c.parse::<f64>().ok());
            // The host's column holds its stated SD; the card's, the
            // record's own error, stated as the host states it.
            let point = |at: usize, sd: fn(f64) -> f64| {
                Some(KickPoint {
                    speed_mps: num(at)?,
                    sigma_per_s: num(at + 1)?,
                    sigma_sd_per_s: sd(num(at + 2)?),
                    freq_hz: num(at + 3)?,
                })
            };
            Ok(Line {
                campaign: (cells[cols[0]].to_owned(), num(1).ok_or("no seed")? as u64),
                wobble_speed_mps: num(2).ok_or("no wobble speed")?,
                true_sigma: num(3).ok_or("no true sigma")?,
                host: point(4, |sd| sd),
                card: point(8, card_sd),
            })
        })
        .collect()
}

/// `BEND=MEAN:SD_CONVEX:SD_CONCAVE[,...]`: more bend shape priors for the
/// line.
fn extra_priors() -> Result<Vec<(String, Trend, BendPrior)>, String> {
    let Ok(spec) = std::env::var("BEND") else {
        return Ok(Vec::new());
    };
    spec.split(',')
        .map(|p| {
            let v: Vec<f64> = p.split(':').filter_map(|x| x.parse().ok()).collect();
            let [mean, sd_convex, sd_concave] = v[..] else {
                return Err(format!("BEND: {p} is not MEAN:SD_CONVEX:SD_CONCAVE"));
            };
            let prior = BendPrior {
                mean,
                sd_convex,
                sd_concave,
            };
            Ok((format!("line, bend {p}"), Trend::Line, prior))
        })
        .collect()
}

/// `k` of `n` as a percentage with its binomial standard error.
fn rate(k: usize, n: usize) -> String {
    let p = k as f64 / n.max(1) as f64;
    format!(
        "{k} of {n} ({:.0} ± {:.0} %)",
        100.0 * p,
        100.0 * (p * (1.0 - p) / n.max(1) as f64).sqrt()
    )
}

fn main() -> Result<(), String> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: margin_coverage KICKS.csv")?;
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{path}: {e}"))?;
    let lines = parse(&text)?;
    let verbose = std::env::var("VERBOSE").is_ok();
    for (name, pick) in [
        (
            "host",
            (|l: &Line| l.host.clone()) as fn(&Line) -> Option<KickPoint>,
        ),
        ("card", |l: &Line| l.card.clone()),
    ] {
        // Each measured kick's stated SD and its error, by SD.
        let mut by_sd: Vec<(f64, f64)> = lines
            .iter()
            .filter_map(|l| pick(l).map(|p| (p.sigma_sd_per_s, p.sigma_per_s - l.true_sigma)))
            .collect();
        by_sd.sort_by(|a, b| a.0.total_cmp(&b.0));
        let errors: Vec<f64> = by_sd.iter().map(|(_, e)| *e).collect();
        let z: Vec<f64> = by_sd.iter().map(|(sd, e)| e / sd).collect();
        let mut sizes: Vec<f64> = errors.iter().map(|e| e.abs()).collect();
        sizes.sort_by(f64::total_cmp);
        let at = |q: f64| sizes.get((q * sizes.len() as f64) as usize).copied();
        println!(
            "{name} kicks: sigma error mean {:+.3} 1/s; |error| median {:.3}, 90th percentile {:.3} 1/s",
            errors.iter().sum::<f64>() / errors.len().max(1) as f64,
            at(0.5).unwrap_or(f64::NAN),
            at(0.9).unwrap_or(f64::NAN)
        );
        let within = |k: f64| z.iter().filter(|z| z.abs() <= k).count();
        let rms = (z.iter().map(|z| z * z).sum::<f64>() / z.len().max(1) as f64).sqrt();
        println!(
            "{name} kicks: {} of {} measured; error within 1 stated SD: {}; within 2: {}; \
             RMS of error/SD {rms:.2}",
            z.len(),
            lines.len(),
            rate(within(1.0), z.len()),
            rate(within(2.0), z.len())
        );
        // The calibration's measure: the median |error| / SD is 0.674 in
        // every fifth of the kicks by stated SD when the SDs are right.
        let fifths: Vec<String> = (0..5)
            .map(|q| {
                let mut part: Vec<f64> = z[q * z.len() / 5..(q + 1) * z.len() / 5]
                    .iter()
                    .map(|z| z.abs())
                    .collect();
                part.sort_by(f64::total_cmp);
                part.get(part.len() / 2)
                    .map_or("-".into(), |m| format!("{m:.2}"))
            })
            .collect();
        println!(
            "{name} kicks: median |error| / SD by fifth of stated SD (0.674 if right): {}",
            fifths.join(" ")
        );
    }
    let mut campaigns: BTreeMap<(String, u64), Vec<&Line>> = BTreeMap::new();
    for l in &lines {
        campaigns.entry(l.campaign.clone()).or_default().push(l);
    }
    for (name, pick) in [
        (
            "host",
            (|l: &Line| l.host.clone()) as fn(&Line) -> Option<KickPoint>,
        ),
        ("card", |l: &Line| l.card.clone()),
    ] {
        let mut fits = vec![
            ("line".to_owned(), Trend::Line, BendPrior::DEFAULT),
            ("straight line".to_owned(), Trend::Line, BendPrior::NONE),
            ("quadratic".to_owned(), Trend::Quadratic, BendPrior::DEFAULT),
        ];
        fits.extend(extra_priors()?);
        for (label, trend, prior) in &fits {
            let (trend, prior) = (*trend, *prior);
            let (mut covered, mut within5, mut n) = (0, 0, 0);
            let mut errors = Vec::new();
            for ((variant, seed), kicks) in &campaigns {
                let truth = kicks[0].wobble_speed_mps;
                let points: Vec<KickPoint> = kicks.iter().filter_map(|l| pick(l)).collect();
                let m = predict_bent(&points, trend, prior);
                n += 1;
                let inside =
                    matches!(m.ci95_mps, [Some(lo), Some(hi)] if lo <= truth && truth <= hi);
                covered += usize::from(inside);
                let err = m.wobble_speed_mps.map(|w| w / truth - 1.0);
                within5 += usize::from(err.is_some_and(|e| e.abs() <= 0.05));
                errors.extend(err);
                if verbose {
                    println!(
                        "  {name} {label} {variant} {seed}: true {truth:.3} predicted {:?} ci \
                         {:?} used {} {:?}",
                        m.wobble_speed_mps, m.ci95_mps, m.kicks_used, m.warnings
                    );
                }
            }
            errors.sort_by(f64::total_cmp);
            let mean = errors.iter().sum::<f64>() / errors.len().max(1) as f64;
            println!(
                "{name} kicks, {label}: interval covers the truth in {}; within 5 % in {}; \
                 error mean {:+.1} %, range {:+.1} to {:+.1} %",
                rate(covered, n),
                rate(within5, n),
                100.0 * mean,
                100.0 * errors.first().copied().unwrap_or(f64::NAN),
                100.0 * errors.last().copied().unwrap_or(f64::NAN)
            );
        }
    }
    Ok(())
}
