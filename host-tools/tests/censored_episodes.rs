//! Episodes the data do not show whole are marked censored with what cuts
//! them; no mode is made up at a cut; episodes away from it are unchanged.

mod analysis_support;

use analysis_support::{stdout_of, wobble, wobblog, Ride, FS_HZ};
use serde_json::Value;
use std::f64::consts::TAU;
use wobblog::analysis::{find_episodes, Cut, Episode, Run, Stability};
use wobblog::losses::LostBlocks;

/// Start of the second wobble, s after the first.
const SECOND_AFTER_S: f64 = 20.0;

/// A 50 s ride at 5 m/s with the standard wobble at 14 s and the same again
/// 20 s later.
fn two_wobbles() -> Ride {
    let mut ride = Ride::new(50.0, 5.0, 0.0, 0.0, 0.0);
    for (t, steer) in ride.t_s.iter().zip(&mut ride.steer_deg) {
        *steer += wobble::envelope_deg(t - SECOND_AFTER_S) * (TAU * wobble::FREQ_HZ * t).sin();
    }
    ride
}

/// `run` without the frames in `from_s..to_s`.
fn without(run: &Run, from_s: f64, to_s: f64) -> Run {
    let keep: Vec<usize> = (0..run.len())
        .filter(|&i| !(from_s..to_s).contains(&run.t_s[i]))
        .collect();
    let mut cut = Run {
        summary: run.summary.clone(),
        ..Run::default()
    };
    for i in keep {
        cut.t_s.push(run.t_s[i]);
        cut.steer_deg.push(run.steer_deg[i]);
        cut.speed_mps.push(run.speed_mps[i]);
        cut.gyro_dps.push(run.gyro_dps[i]);
        cut.accel_g.push(run.accel_g[i]);
    }
    cut
}

fn first_wobble(episodes: &[Episode]) -> &Episode {
    episodes
        .iter()
        .find(|e| (e.onset_s - wobble::ONSET_S).abs() < 0.5)
        .expect("the first wobble")
}

fn assert_same(a: &Episode, b: &Episode) {
    analysis_support::assert_same_episode(a, b);
    assert!(!a.censored && !b.censored);
}

/// Every episode after a cut at `t_cut` starts at it, and none of them is
/// a mode fitted from the cut's edge.
fn assert_nothing_made_up_after(episodes: &[Episode], t_cut: f64, cut: Cut) {
    for e in episodes.iter().filter(|e| e.onset_s >= t_cut) {
        assert!(e.onset_s - t_cut < 0.05, "{e:?}");
        assert_eq!(e.cut_at_start, Some(cut), "{e:?}");
        assert_eq!(e.stability, Stability::Unstable, "{e:?}");
        assert!(e.censored);
    }
}

#[test]
fn whole_episodes_are_not_censored() {
    let episodes = find_episodes(&two_wobbles().run());
    assert_eq!(episodes.len(), 2, "{episodes:#?}");
    for e in &episodes {
        assert!(
            !e.censored && e.cut_at_start.is_none() && e.cut_at_end.is_none(),
            "{e:?}"
        );
        assert_eq!(e.stability, Stability::Unstable);
    }
}

#[test]
fn an_episode_cut_by_lost_blocks_is_censored_and_the_other_is_unchanged() {
    let run = two_wobbles().run();
    let whole = find_episodes(&run);
    // A block's worth of frames lost while the second wobble grows.
    let (from, to) = (
        wobble::ONSET_S + SECOND_AFTER_S + 1.9,
        wobble::ONSET_S + SECOND_AFTER_S + 2.12,
    );
    let mut cut = without(&run, from, to);
    let before = cut.t_s[cut.t_s.partition_point(|&t| t < from) - 1];
    let after = cut.t_s[cut.t_s.partition_point(|&t| t < from)];
    cut.summary.losses.lost_blocks.push(LostBlocks {
        first_block: 100,
        last_block: 100,
        frames: 22,
        from_s: Some(before),
        to_s: after,
    });
    let episodes = find_episodes(&cut);
    assert_same(first_wobble(&whole), first_wobble(&episodes));
    let cut_one = episodes
        .iter()
        .find(|e| e.cut_at_end == Some(Cut::LostBlocks))
        .unwrap_or_else(|| panic!("{episodes:#?}"));
    assert!(cut_one.censored);
    assert!((cut_one.end_s - before).abs() < 1e-9, "{cut_one:?}");
    assert!(cut_one.peak_amp_deg < wobble::PEAK_DEG, "{cut_one:?}");
    assert_nothing_made_up_after(&episodes, after, Cut::LostBlocks);
}

#[test]
fn dropouts_and_time_jumps_are_named_as_the_cut() {
    let run = two_wobbles().run();
    let t_gap = wobble::ONSET_S + SECOND_AFTER_S + 1.9;
    // Frames dropped by the logger: nothing in the losses accounts for them.
    let dropped = without(&run, t_gap, t_gap + 0.3);
    let episodes = find_episodes(&dropped);
    assert!(
        episodes.iter().any(|e| e.cut_at_end == Some(Cut::Dropout)),
        "{episodes:#?}"
    );
    // The clock jumps 1000 s forward.
    let mut jumped = run.clone();
    let at = jumped.t_s.partition_point(|&t| t < t_gap);
    for t in &mut jumped.t_s[at..] {
        *t += 1000.0;
    }
    jumped
        .summary
        .losses
        .time_jumps
        .push((jumped.t_s[at - 1], jumped.t_s[at]));
    let episodes = find_episodes(&jumped);
    assert!(
        episodes.iter().any(|e| e.cut_at_end == Some(Cut::TimeJump)),
        "{episodes:#?}"
    );
    assert_nothing_made_up_after(&episodes, jumped.t_s[at], Cut::TimeJump);
    assert_same(first_wobble(&find_episodes(&run)), first_wobble(&episodes));
}

#[test]
fn an_episode_cut_by_the_end_of_the_data_is_censored() {
    let run = two_wobbles().run();
    let whole = find_episodes(&run);
    let end_s = wobble::ONSET_S + SECOND_AFTER_S + 2.0;
    let cut = without(&run, end_s, f64::INFINITY);
    let episodes = find_episodes(&cut);
    assert_same(first_wobble(&whole), first_wobble(&episodes));
    let last = episodes.last().unwrap();
    assert_eq!(last.cut_at_end, Some(Cut::DataEnd), "{episodes:#?}");
    assert!(last.censored && last.cut_at_start.is_none());
    assert!(last.peak_amp_deg < wobble::PEAK_DEG);
    // Cut at the start as well: a run that begins mid-wobble.
    let late = without(&run, 0.0, wobble::ONSET_S + 1.0);
    let episodes = find_episodes(&late);
    let first = &episodes[0];
    assert_eq!(first.cut_at_start, Some(Cut::DataStart), "{episodes:#?}");
    assert!(
        (first.onset_s - (wobble::ONSET_S + 1.0)).abs() < 0.02,
        "{first:?}"
    );
    // Its onset is unknown, so it gives no wobble speed.
    assert_eq!(
        wobblog::analysis::wobble_speed_mps(&episodes[..1]),
        None,
        "{first:?}"
    );
}

#[test]
fn a_log_cut_short_reports_the_episode_censored_in_json_table_and_summary() {
    let dir = tempfile::tempdir().unwrap();
    let mut ride = Ride::new(16.0, 5.0, 0.0, 0.0, 0.0);
    // Cut while the wobble still grows (peak at 16.3 s).
    ride.t_s.truncate(((15.9 - 1.0) * FS_HZ) as usize);
    let n = ride.t_s.len();
    ride.steer_deg.truncate(n);
    ride.speed_mps.truncate(n);
    ride.gyro_dps.truncate(n);
    ride.accel_g.truncate(n);
    ride.roll_deg.truncate(n);
    let log = dir.path().join("RUN00001.WBL");
    analysis_support::write_log(&log, &ride, &analysis_support::Extras::default());

    let json: Value =
        serde_json::from_str(&stdout_of(wobblog().args(["wobble", "--json"]).arg(&log))).unwrap();
    let e = &json["episodes"][0];
    assert_eq!(e["censored"], true, "{json:#}");
    assert_eq!(e["cut_at_end"], "data_end");
    assert_eq!(e["cut_at_start"], Value::Null);
    let table = stdout_of(wobblog().arg("wobble").arg(&log));
    assert!(table.contains("stability  source     censored"), "{table}");
    assert!(
        table
            .trim_end()
            .ends_with("unstable   episode    end: data_end"),
        "{table}"
    );

    let csv = stdout_of(
        wobblog()
            .arg("summary")
            .arg(dir.path())
            .args(["--format", "csv"]),
    );
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let row: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| row[header.iter().position(|h| *h == name).unwrap()];
    assert_eq!(col("episodes"), "1");
    assert_eq!(col("censored_episodes"), "1");
}
