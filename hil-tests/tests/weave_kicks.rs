//! Simulated weave kick campaigns on seven published bicycles
//! (`hil-tests/src/corpus/simulated/weave.rs`): the host's weave kicks
//! against every kick's true weave eigenvalue, and each campaign's
//! predicted weave speed against the bicycle's.

use std::sync::OnceLock;

use wobble_hil::corpus::signal::WHEEL_CIRCUMFERENCE_M;
use wobble_hil::corpus::simulated::weave::{self, Campaign, Plan, WeaveKickTruth, BICYCLES};
use wobblog::analysis::margin::weave::predict_weave;
use wobblog::analysis::margin::{KickPoint, Trend};
use wobblog::analysis::{find_episodes, find_kicks, find_mode_kicks, Episode, Kick, KickMode, Run};

/// Seeds of the campaigns, from `seed()` on: the stated SD was
/// calibrated on 300-306, 400-406 and 500-506 (`analysis::weave`), so
/// these are others.
/// (`WEAVE_SEED` in the environment runs others.)
fn seed() -> u64 {
    std::env::var("WEAVE_SEED")
        .ok()
        .map_or(700, |s| s.parse().expect("WEAVE_SEED: a number"))
}

/// One campaign per bicycle, written and read back, with the host's weave
/// kicks of each pass.
struct Loaded {
    campaign: Campaign,
    kicks: Vec<Vec<Kick>>,
    /// What the wobble's analyses find in the same logs: kicks and
    /// episodes, per pass.
    wobble: Vec<(Vec<Kick>, Vec<Episode>)>,
}

fn loaded() -> &'static [Loaded] {
    static L: OnceLock<Vec<Loaded>> = OnceLock::new();
    L.get_or_init(|| {
        let tmp = tempfile::tempdir().unwrap();
        BICYCLES
            .iter()
            .zip(seed()..)
            .map(|(b, seed)| {
                let campaign = weave::simulate(b, &Plan::default(), seed).unwrap();
                let runs: Vec<Run> = campaign
                    .write(&tmp.path().join(b))
                    .unwrap()
                    .iter()
                    .map(|log| Run::load(log).unwrap())
                    .collect();
                let kicks = runs
                    .iter()
                    .map(|run| find_mode_kicks(run, WHEEL_CIRCUMFERENCE_M, KickMode::Weave))
                    .collect();
                let wobble = runs
                    .iter()
                    .map(|run| (find_kicks(run, WHEEL_CIRCUMFERENCE_M), find_episodes(run)))
                    .collect();
                Loaded {
                    campaign,
                    kicks,
                    wobble,
                }
            })
            .collect()
    })
}

/// Every (truth, measured kick) pair; a missed kick pairs with `None`.
fn pairs() -> Vec<(&'static WeaveKickTruth, Option<&'static Kick>)> {
    let mut out = Vec::new();
    for l in loaded() {
        for (pass, kicks) in l.campaign.passes.iter().zip(&l.kicks) {
            let log = format!("{}.wbl", pass.name);
            for truth in l.campaign.kicks.iter().filter(|k| k.log == log) {
                out.push((
                    truth,
                    kicks.iter().find(|k| (k.t_s - truth.t_s).abs() < 1.0),
                ));
            }
        }
    }
    out
}

/// The measure: frequency within 0.05 Hz and damping within 0.3
/// 1/s of the truth for most kicks; 85 % found; hardly a kick found
/// where none was given; the stated SD honest (two thirds of the errors
/// within one, 85 % within two).
#[test]
fn weave_kicks_meet_their_accuracy() {
    let pairs = pairs();
    let found: Vec<(&WeaveKickTruth, &Kick)> = pairs
        .iter()
        .filter_map(|(t, k)| k.map(|k| (*t, k)))
        .collect();
    let within = |t: &WeaveKickTruth, k: &Kick| {
        (k.freq_hz - t.freq_hz).abs() <= 0.05 && (k.sigma_per_s - t.sigma_per_s).abs() <= 0.3
    };
    let good = found.iter().filter(|(t, k)| within(t, k)).count();
    let z: Vec<f64> = found
        .iter()
        .map(|(t, k)| ((k.sigma_per_s - t.sigma_per_s) / k.sigma_sd_per_s).abs())
        .collect();
    let share = |limit: f64| z.iter().filter(|z| **z <= limit).count() as f64 / z.len() as f64;
    let n = pairs.len();
    eprintln!(
        "{n} kicks, {} found, {good} within 0.05 Hz and 0.3 1/s; |error|/SD within 1: {:.2}, \
         within 2: {:.2}",
        found.len(),
        share(1.0),
        share(2.0)
    );
    assert!(found.len() * 20 >= n * 17, "{} of {n} found", found.len());
    assert!(good * 10 >= n * 8, "{good} of {n} within");
    assert!((0.58..0.78).contains(&share(1.0)), "{}", share(1.0));
    assert!(share(2.0) >= 0.85, "{}", share(2.0));
    let extra: usize = loaded()
        .iter()
        .flat_map(|l| &l.kicks)
        .map(Vec::len)
        .sum::<usize>()
        - found.len();
    // The road's noise now and then sets the weave ringing as a kick
    // would (0.1-0.5 degrees of roll): one in a hundred at most.
    assert!(extra * 100 <= n, "{extra} kicks found where none was given");
}

/// Each campaign's 95 % interval holds the bicycle's weave speed, lies
/// below its kicks, and is bounded; the estimates are within 0.3 m/s.
#[test]
fn each_campaign_brackets_its_weave_speed() {
    for l in loaded() {
        let points: Vec<KickPoint> = l.kicks.iter().flatten().map(KickPoint::from).collect();
        let m = predict_weave(&points, Trend::Line);
        let truth = l.campaign.weave_speed_mps;
        let [lo, hi] = m.ci95_mps;
        eprintln!(
            "{}: truth {truth:.3}, predicted {:?} [{lo:?}, {hi:?}] from {} kicks",
            l.campaign.bicycle, m.weave_speed_mps, m.kicks_used
        );
        let (lo, hi) = (lo.unwrap(), hi.unwrap());
        let slowest = m.speed_range_mps.unwrap()[0];
        assert!(lo <= truth && truth <= hi && hi < slowest, "{m:?}");
        assert!((m.weave_speed_mps.unwrap() - truth).abs() < 0.3, "{m:?}");
    }
}

/// No weave ring-down is called a wobble: the wobble's kick search and
/// episode search find nothing in the weave campaigns' logs.
#[test]
fn no_weave_ring_down_is_called_wobble() {
    for l in loaded() {
        for (pass, (kicks, episodes)) in l.campaign.passes.iter().zip(&l.wobble) {
            assert!(kicks.is_empty(), "{}: {kicks:?}", pass.name);
            assert!(episodes.is_empty(), "{}: {episodes:?}", pass.name);
        }
    }
}

/// Noise-free ring-downs of the benchmark's Whipple model, one kick at
/// 4.7-6.4 m/s each, fed to the search directly: frequency and damping
/// within 0.01 of the model's weave eigenvalue (the band-pass's answer to
/// the kick and the capsize's drift taken up by the trend fitted beside
/// the ring).
#[test]
fn noise_free_ring_downs_give_the_weave_eigenvalue() {
    let model = weave::model("Benchmark").unwrap();
    for u in [4.7, 5.15, 5.6, 6.0, 6.4] {
        let (sigma, freq) = weave::weave_at(&model, u).unwrap();
        let ring = weave::ring_down(&model, u, 14.0).unwrap();
        let mut run = Run::default();
        for (i, rate) in ring.iter().enumerate() {
            run.t_s.push(i as f64 / 100.0);
            run.steer_deg.push(0.0);
            run.speed_mps.push(u);
            run.gyro_dps.push([*rate, 0.0, 0.0]);
            run.accel_g.push([0.0, 0.0, 1.0]);
        }
        let kicks = find_mode_kicks(&run, WHEEL_CIRCUMFERENCE_M, KickMode::Weave);
        assert_eq!(kicks.len(), 1, "{u}: {kicks:?}");
        let k = &kicks[0];
        assert!((k.freq_hz - freq).abs() < 0.01, "{u}: {k:?} vs {freq}");
        assert!(
            (k.sigma_per_s - sigma).abs() < 0.01,
            "{u}: {k:?} vs {sigma}"
        );
    }
}
