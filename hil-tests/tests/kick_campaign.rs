//! Simulated kick-test campaigns with a known answer
//! (`hil-tests/src/corpus/simulated/campaign.rs`): the host's kick
//! extractor against every kick's true eigenvalue, and the campaign's
//! prediction against the bicycle's true wobble speed.

use std::sync::OnceLock;

use wobble_hil::corpus::signal::WHEEL_CIRCUMFERENCE_M;
use wobble_hil::corpus::simulated::campaign::{self, Campaign, KickTruth, Plan};
use wobblog::analysis::campaign_kicks::{campaign_kicks, Prefer, Source};
use wobblog::analysis::margin::{predict, KickPoint};
use wobblog::analysis::{find_kicks, Kick, Run};

/// One campaign per variant, knocks and pushes, written and read back.
struct Loaded {
    campaign: Campaign,
    runs: Vec<Run>,
}

fn loaded() -> &'static [Loaded] {
    static L: OnceLock<Vec<Loaded>> = OnceLock::new();
    L.get_or_init(|| {
        let tmp = tempfile::tempdir().unwrap();
        let mut out = Vec::new();
        for (k, v) in campaign::variants().unwrap().iter().enumerate() {
            for (p, plan) in [Plan::default(), Plan::default().with_push()]
                .into_iter()
                .enumerate()
            {
                let seed = 10 + 2 * k as u64 + p as u64;
                let c = campaign::simulate(v, &plan, seed).unwrap();
                let dir = tmp.path().join(format!("{}_{seed}", v.name));
                let runs = c
                    .write(&dir)
                    .unwrap()
                    .iter()
                    .map(|log| Run::load(log).unwrap())
                    .collect();
                out.push(Loaded { campaign: c, runs });
            }
        }
        out
    })
}

/// The measured kick matching a true one (within 0.5 s of its start).
fn matching<'a>(kicks: &'a [Kick], truth: &KickTruth) -> Option<&'a Kick> {
    kicks.iter().find(|k| (k.t_s - truth.t_s).abs() < 0.5)
}

#[test]
fn each_variant_has_a_wobble_speed_and_rides_below_it() {
    for l in loaded() {
        let c = &l.campaign;
        assert!(
            (2.5..8.0).contains(&c.wobble_speed_mps),
            "{}: {}",
            c.variant,
            c.wobble_speed_mps
        );
        for k in &c.kicks {
            assert!(
                k.sigma_per_s < 0.0 && k.speed_mps < c.wobble_speed_mps,
                "{k:?}"
            );
        }
    }
}

#[test]
fn kick_extractor_meets_its_accuracy() {
    let (mut n, mut good, mut found) = (0, 0, 0);
    let mut z = Vec::new();
    let mut errors = Vec::new();
    let mut table = String::new();
    for l in loaded() {
        for (pass, run) in l.campaign.passes.iter().zip(&l.runs) {
            let kicks = find_kicks(run, WHEEL_CIRCUMFERENCE_M);
            let log = format!("{}.wbl", pass.fixture.truth.name);
            for truth in l.campaign.kicks.iter().filter(|k| k.log == log) {
                if !(1.5..=6.0).contains(&truth.speed_mps) {
                    continue;
                }
                n += 1;
                let m = matching(&kicks, truth);
                let ok = m.is_some_and(|m| {
                    (m.sigma_per_s - truth.sigma_per_s).abs() <= 0.3
                        && (m.freq_hz - truth.freq_hz).abs() <= 0.2
                });
                found += usize::from(m.is_some());
                if let Some(m) = m {
                    z.push((m.sigma_per_s - truth.sigma_per_s) / m.sigma_sd_per_s);
                    errors.push((
                        (m.sigma_per_s - truth.sigma_per_s).abs(),
                        (m.freq_hz - truth.freq_hz).abs(),
                    ));
                }
                good += usize::from(ok);
                table.push_str(&format!(
                    "{log} u {:.2} true s {:.2} f {:.2} amp {:.2} | {}\n",
                    truth.speed_mps,
                    truth.sigma_per_s,
                    truth.freq_hz,
                    truth.amp_deg,
                    m.map_or("missed".into(), |m| format!(
                        "s {:.2} ± {:.2} f {:.2} amp {:.2} fit {:.2}-{:.2} res {:.2}{}",
                        m.sigma_per_s,
                        m.sigma_sd_per_s,
                        m.freq_hz,
                        m.amp_deg,
                        m.fit_s[0],
                        m.fit_s[1],
                        m.residual_rel,
                        if ok { "" } else { "  <<" }
                    ))
                ));
            }
        }
    }
    let within_2sd = z.iter().filter(|z| z.abs() <= 2.0).count();
    let mut es: Vec<f64> = errors.iter().map(|e| e.0).collect();
    let mut ef: Vec<f64> = errors.iter().map(|e| e.1).collect();
    es.sort_by(f64::total_cmp);
    ef.sort_by(f64::total_cmp);
    let q = |v: &[f64], p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
    eprintln!(
        "{table}{good} of {n} within 0.3 1/s and 0.2 Hz, {found} found; \
         |sigma error| median {:.3} 90 % {:.3} 1/s; |f error| median {:.3} 90 % {:.3} Hz; \
         {within_2sd} of {} within 2 stated SD",
        q(&es, 0.5),
        q(&es, 0.9),
        q(&ef, 0.5),
        q(&ef, 0.9),
        z.len()
    );
    assert!(n >= 100, "{n} kicks");
    assert!(good * 10 >= n * 8, "{good} of {n}\n{table}");
    // The stated SD is calibrated (`kicks::stated_sd`, on other seeds):
    // about 95 % of the errors within two of it (92 % on 3600 kicks).
    assert!(
        within_2sd * 100 >= z.len() * 85,
        "{within_2sd} of {}",
        z.len()
    );
}

/// The logs hold the kick records the board writes (`encode --detect`):
/// `margin` takes them, re-measured by the host where it finds the kick
/// too, and the host's re-measurement is as near the truth as the card's
/// record (median error over the same kicks within 10 %: seeds 100-102
/// give 0.026 1/s for the host, 0.025 for the card, whose fit takes the
/// high-pass's transient out).
#[test]
fn card_records_are_used_and_refined_by_the_host() {
    let (mut card_err, mut host_err, mut sources) = (Vec::new(), Vec::new(), Vec::new());
    let (mut passes, mut with_records) = (0, 0);
    for l in loaded() {
        for (pass, run) in l.campaign.passes.iter().zip(&l.runs) {
            passes += 1;
            with_records += usize::from(!run.summary.kick_records.is_empty());
            let log = format!("{}.wbl", pass.fixture.truth.name);
            for k in campaign_kicks(run, WHEEL_CIRCUMFERENCE_M, Prefer::Best) {
                sources.push(k.source);
                let Some(truth) = l
                    .campaign
                    .kicks
                    .iter()
                    .find(|t| t.log == log && (t.t_s - k.t_s).abs() < 0.5)
                else {
                    continue;
                };
                if let (Some(c), Some(h)) = (&k.card, &k.host) {
                    card_err.push((c.sigma_per_s - truth.sigma_per_s).abs());
                    host_err.push((h.sigma_per_s - truth.sigma_per_s).abs());
                }
            }
        }
    }
    // The board measures nearly every kick (844 of 864 on seeds 100-111).
    assert!(
        with_records * 10 >= passes * 9,
        "{with_records} of {passes}"
    );
    let both = sources.iter().filter(|s| **s == Source::CardHost).count();
    assert!(both * 10 >= sources.len() * 9, "{sources:?}");
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (c, h) = (median(card_err), median(host_err));
    eprintln!(
        "{both} of {} kicks card-host; median |sigma error| card {c:.3}, host {h:.3} 1/s",
        sources.len()
    );
    assert!(h < 1.1 * c, "host {h} card {c}");
}

/// Every kick of a campaign as `margin` takes it (the card's records,
/// re-measured by the host), as the regression takes it.
fn points(l: &Loaded) -> Vec<KickPoint> {
    l.runs
        .iter()
        .flat_map(|run| campaign_kicks(run, WHEEL_CIRCUMFERENCE_M, Prefer::Best))
        .map(|k| KickPoint::from(&k))
        .collect()
}

#[test]
fn margin_predicts_each_bicycle_within_5_percent() {
    let mut table = String::new();
    let mut bad = 0;
    for l in loaded() {
        let truth = l.campaign.wobble_speed_mps;
        let m = predict(&points(l));
        let ok = m
            .wobble_speed_mps
            .is_some_and(|w| (w / truth - 1.0).abs() <= 0.05);
        bad += usize::from(!ok);
        table.push_str(&format!(
            "{} seed {}: true {truth:.3} predicted {:?} ci {:?} used {} rejected {} {:?}\n",
            l.campaign.variant,
            l.campaign.seed,
            m.wobble_speed_mps,
            m.ci95_mps,
            m.kicks_used,
            m.kicks_rejected,
            m.warnings
        ));
    }
    eprintln!("{table}");
    assert_eq!(bad, 0, "{table}");
}

/// Every kick of `c` as the host measures it from each pass's steering
/// (without the card round trip, to keep it short).
fn host_points(c: &Campaign) -> Vec<KickPoint> {
    c.passes
        .iter()
        .flat_map(|p| {
            let rows = wobble_hil::corpus::parse_rows(&p.fixture.csv).unwrap();
            let run = Run {
                t_s: rows.iter().map(|r| r.t_s).collect(),
                steer_deg: rows.iter().map(|r| f64::from(r.steer_deg)).collect(),
                speed_mps: rows.iter().map(|r| f64::from(r.speed_mps)).collect(),
                ..Run::default()
            };
            find_kicks(&run, WHEEL_CIRCUMFERENCE_M)
        })
        .map(|k| KickPoint::from(&k))
        .collect()
}

/// Coverage of the 95 % interval and the prediction's error over more
/// campaigns (3 seeds on each of the four bicycles, kicks measured by the
/// host). Over 48 campaigns (seeds 100-111) the interval covered the truth
/// in 47 (98 ± 2 %), over 200 not tuned on (seeds 200-249) in 193 (96 ± 1
/// %), over 200 more (seeds 300-349) in the share
/// `host-tools/docs/kick-testing.md` gives (`examples/margin_coverage.rs`).
/// This test guards them: at least 10 of these 12 covered (11 are), none
/// off by more than 5 % (the worst is 4.4 %).
#[test]
fn interval_coverage_and_error_over_seeds() {
    let variants = campaign::variants().unwrap();
    let (mut covered, mut n, mut worst) = (0, 0, 0.0f64);
    let mut table = String::new();
    for v in &variants {
        for seed in 100..103 {
            let c = campaign::simulate(v, &Plan::default(), seed).unwrap();
            let m = predict(&host_points(&c));
            let truth = c.wobble_speed_mps;
            n += 1;
            let inside = matches!(m.ci95_mps, [Some(lo), Some(hi)] if lo <= truth && truth <= hi);
            covered += usize::from(inside);
            let err = m
                .wobble_speed_mps
                .map_or(f64::INFINITY, |w| (w / truth - 1.0).abs());
            worst = worst.max(err);
            table.push_str(&format!(
                "{} {seed}: true {truth:.3} predicted {:?} ci {:?}\n",
                v.name, m.wobble_speed_mps, m.ci95_mps
            ));
        }
    }
    eprintln!(
        "{table}covered {covered} of {n}; worst error {:.1} %",
        100.0 * worst
    );
    assert!(covered >= 10, "{table}covered {covered} of {n}");
    assert!(worst <= 0.05, "{table}worst {worst}");
}

/// Bicycles nothing was tuned on (`campaign::unseen_variants`: the
/// paper's test bicycle re-derived for the model, with its 55 kg rider,
/// and the same with a 1 kg handlebar bag): the prediction within 5 % of
/// the wobble speed and the interval holding it, on two campaigns each
/// (over 50, seeds 200-249: 49 and 50 within 5 %, 50 and 49 covered;
/// `host-tools/docs/kick-testing.md`).
#[test]
fn margin_holds_on_a_bicycle_never_tuned_on() {
    let unseen = campaign::unseen_variants().unwrap();
    for name in ["paper-light-rider", "paper-bar-bag"] {
        let v = unseen
            .iter()
            .find(|v| v.name == name)
            .expect("the unseen bicycle");
        for seed in 200..202 {
            let c = campaign::simulate(v, &Plan::default(), seed).unwrap();
            let m = predict(&host_points(&c));
            let truth = c.wobble_speed_mps;
            let w = m.wobble_speed_mps.expect("a prediction");
            assert!(
                (w / truth - 1.0).abs() <= 0.05,
                "{name} {seed}: {truth} {m:?}"
            );
            assert!(
                matches!(m.ci95_mps, [Some(lo), Some(hi)] if lo <= truth && truth <= hi),
                "{name} {seed}: {truth} {m:?}"
            );
        }
    }
}

/// `--model`: the test bicycle's file fitted (steering-head stiffness and
/// damping) to the kicks of the test bicycle's and the damped head's
/// campaigns gives their wobble speeds within 5 %, inside its interval.
#[test]
fn model_informed_estimate_finds_the_wobble_speed() {
    let params = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../host-tools/bicycle-model/params/test-bicycle.toml");
    let keys: Vec<String> = wobblog::cmd::margin_model::DEFAULT_PARAMS
        .iter()
        .map(|k| (*k).to_owned())
        .collect();
    for l in loaded()
        .iter()
        .filter(|l| ["test-bicycle", "head-damping"].contains(&l.campaign.variant.as_str()))
    {
        let kicks: Vec<(f64, f64, f64, f64)> = points(l)
            .iter()
            .map(|k| (k.speed_mps, k.freq_hz, k.sigma_per_s, k.sigma_sd_per_s))
            .collect();
        let m = wobblog::cmd::margin_model::estimate(&params, &keys, &kicks, 0).unwrap();
        let truth = l.campaign.wobble_speed_mps;
        let w = m.wobble_speed_mps.unwrap();
        assert!(
            (w / truth - 1.0).abs() <= 0.05,
            "{} {truth}: {m:?}",
            l.campaign.variant
        );
        let [lo, hi] = m.ci95_mps;
        assert!(
            lo.unwrap() <= truth && truth <= hi.unwrap(),
            "{} {truth}: {m:?}",
            l.campaign.variant
        );
    }
}
