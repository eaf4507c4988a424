//! `decode --columns ...,roll_deg,steer_bp_deg,wobble_env_deg`: the derived
//! signals in the data, each against an independent reference: the causal
//! band against the analysis's filter run over the decoded steering, the
//! roll against the plot's estimate and the ride's true lean, the envelope
//! against the wobble the ride was made with.

mod analysis_support;

use analysis_support::{decode_to, standard_log, wobble};
use wobblog::analysis::filter::{band_pass_causal, WOBBLE_BAND_HZ};
use wobblog::analysis::{estimate_roll_deg, Run};
use wobblog::export::derived::{ENVELOPE_WINDOW_S, GROUP_DELAY_7HZ_S};

#[test]
fn derived_columns_are_the_analyses_signals() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00001.WBL");
    let (ride, _) = standard_log(&log);
    let csv = dir.path().join("d.csv");
    let out = decode_to(
        &log,
        &csv,
        &[
            "--columns",
            "t_s,steer_deg,roll_deg,steer_bp_deg,wobble_env_deg",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("t_s,steer_deg,roll_deg,steer_bp_deg,wobble_env_deg")
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    let run = Run::load(&log).unwrap();
    assert_eq!(rows.len(), run.len());
    let col = |k: usize| rows.iter().map(|r| r[k]).collect::<Vec<f64>>();
    let (t, steer, roll, bp, env) = (col(0), col(1), col(2), col(3), col(4));

    // The causal band: the analysis's filter over the decoded steering.
    let reference = band_pass_causal(&steer, WOBBLE_BAND_HZ, 100.0);
    for (a, b) in bp.iter().zip(&reference) {
        assert!((a - b).abs() < 1e-9, "{a} vs {b}");
    }
    // The roll: the plot's estimate, and within 1.5 degrees RMS of the
    // ride's true lean (corners of 15 degrees and a weave).
    assert_eq!(roll, estimate_roll_deg(&run));
    let rms = (roll
        .iter()
        .zip(&ride.roll_deg)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        / roll.len() as f64)
        .sqrt();
    assert!(rms < 1.5, "{rms}");
    // The envelope: the ride's wobble peaks at 2 degrees and decays at
    // 5/s; the envelope's largest value is near it, late by the band's
    // delay and about half the window.
    let (i_max, max) = env
        .iter()
        .enumerate()
        .fold((0, 0.0f64), |m, (i, &e)| if e > m.1 { (i, e) } else { m });
    assert!(
        (max - wobble::PEAK_DEG).abs() < 0.35 * wobble::PEAK_DEG,
        "{max}"
    );
    let late = t[i_max] - wobble::peak_s();
    assert!(
        late > 0.0 && late < GROUP_DELAY_7HZ_S + ENVELOPE_WINDOW_S,
        "{late}"
    );
    // Nothing shows before the wobble: a causal band, a trailing window.
    let onset = t.iter().position(|&x| x >= wobble::ONSET_S).unwrap();
    assert!(env[..onset].iter().all(|e| *e < 0.2), "before the onset");
}

/// Without derived columns the output is as it was: none of them in the
/// default columns.
#[test]
fn derived_columns_are_opt_in() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00001.WBL");
    standard_log(&log);
    let csv = dir.path().join("d.csv");
    assert!(decode_to(&log, &csv, &[]).status.success());
    let header = std::fs::read_to_string(&csv).unwrap();
    let header = header.lines().next().unwrap();
    for name in ["roll_deg", "steer_bp_deg", "wobble_env_deg"] {
        assert!(!header.contains(name), "{header}");
    }
}
