//! The analyses stream: episodes and the roll estimate of a run do not
//! depend on how many frames are held at once, and what is held stays
//! bounded however long the run.

mod analysis_support;

use std::f64::consts::TAU;

use analysis_support::{assert_same_episode as assert_same, wobble, Ride, FS_HZ};
use wobblog::analysis::kicks::{self, KickSearch};
use wobblog::analysis::roll::RollStream;
use wobblog::analysis::search::EpisodeSearch;
use wobblog::analysis::{Cut, Episode, Run, Stability};
use wobblog::losses::Losses;

/// Chunks so large that the whole run is analysed at once: the reference.
const WHOLE: usize = 1 << 24;

/// A ride of `minutes` at 5 m/s with corners, weave and the standard wobble
/// every 40 s.
fn wobbly_ride(minutes: f64) -> Run {
    let mut ride = Ride::new(60.0 * minutes, 5.0, 10.0, 1.0, 0.5);
    for (t, steer) in ride.t_s.iter().zip(&mut ride.steer_deg) {
        let k = ((t - wobble::ONSET_S) / 40.0).floor().max(0.0);
        if k > 0.0 {
            *steer += wobble::envelope_deg(t - 40.0 * k) * (TAU * wobble::FREQ_HZ * t).sin();
        }
    }
    ride.run()
}

fn episodes(run: &Run, chunk: usize) -> (Vec<Episode>, usize) {
    let mut search = EpisodeSearch::with_chunk(run.sample_rate_hz(), chunk);
    for i in 0..run.len() {
        search.push(run.t_s[i], run.steer_deg[i], run.speed_mps[i]);
    }
    let held = search.most_held();
    (search.finish(&Losses::default()), held)
}

#[test]
fn episodes_do_not_depend_on_the_window() {
    let run = wobbly_ride(12.0);
    let (whole, held) = episodes(&run, WHOLE);
    assert_eq!(held, run.len());
    // One wobble every 40 s, the first at 54 s; the last reaches the end.
    assert!(whole.len() >= 16, "{whole:#?}");
    for e in whole.iter().filter(|e| !e.censored) {
        assert_eq!(e.stability, Stability::Unstable);
        assert!((e.sigma_per_s - wobble::SIGMA_PER_S).abs() < 0.2, "{e:?}");
    }
    for chunk in [6000, 7919, 20_000] {
        let (streamed, held) = episodes(&run, chunk);
        assert!(held <= 4 * chunk + 1, "{held} frames held");
        assert_eq!(streamed.len(), whole.len(), "chunk {chunk}");
        for (a, b) in streamed.iter().zip(&whole) {
            assert_same(a, b);
        }
    }
}

/// A wobble that grows and then holds its size for longer than the window
/// can hold is measured in pieces: the first has the growth the data show,
/// and every piece says it was cut by the window.
#[test]
fn an_overlong_wobble_is_measured_in_censored_pieces() {
    let mut run = Ride::new(900.0, 5.0, 0.0, 0.0, 0.0).run();
    let peak_s = wobble::peak_s();
    for (t, steer) in run.t_s.iter().zip(&mut run.steer_deg) {
        let held = if *t < peak_s {
            wobble::envelope_deg(*t)
        } else if *t < 800.0 {
            wobble::PEAK_DEG
        } else {
            0.0
        };
        *steer = held * (TAU * wobble::FREQ_HZ * t).sin();
    }
    let (whole, _) = episodes(&run, WHOLE);
    assert_eq!(whole.len(), 1, "{whole:#?}");
    assert!(!whole[0].censored);
    let chunk = 6000;
    let (pieces, held) = episodes(&run, chunk);
    assert!(held <= 4 * chunk + 1, "{held} frames held");
    let first = &pieces[0];
    assert_eq!(first.stability, Stability::Unstable);
    assert_eq!(first.cut_at_end, Some(Cut::Overlong), "{first:?}");
    // The climb is the one put in, as the whole run's analysis finds it.
    for e in [first, &whole[0]] {
        assert!((e.onset_s - wobble::ONSET_S).abs() < 0.1, "{e:?}");
        assert!((e.sigma_per_s - wobble::SIGMA_PER_S).abs() < 0.05, "{e:?}");
    }
    for piece in &pieces[1..] {
        assert_eq!(piece.cut_at_start, Some(Cut::Overlong), "{piece:?}");
    }
}

/// Wobbles held for 100 s, 20 s apart, each for less than the window can
/// hold: they are measured whole, with or without a window, and none is
/// called cut by it.
#[test]
fn long_wobbles_the_window_can_hold_are_measured_whole() {
    let mut run = Ride::new(600.0, 5.0, 0.0, 0.0, 0.0).run();
    for (t, steer) in run.t_s.iter().zip(&mut run.steer_deg) {
        let u = (t - 20.0).rem_euclid(120.0);
        let held = if *t < 20.0 || u > 100.0 + wobble::peak_s() {
            0.0
        } else {
            wobble::envelope_deg(u.min(wobble::peak_s()))
        };
        *steer = held * (TAU * wobble::FREQ_HZ * t).sin();
    }
    let (whole, _) = episodes(&run, WHOLE);
    assert!(whole.len() >= 4, "{whole:#?}");
    for chunk in [6000, 7919] {
        let (streamed, _) = episodes(&run, chunk);
        assert_eq!(streamed.len(), whole.len(), "chunk {chunk}: {streamed:#?}");
        for (a, b) in streamed.iter().zip(&whole) {
            assert_same(a, b);
            assert!(a.cut_at_start != Some(Cut::Overlong) && a.cut_at_end != Some(Cut::Overlong));
        }
    }
}

/// A wobble from the first frame for longer than the window holds: its
/// first piece is cut at the start by the start of the data, at the end by
/// the window.
#[test]
fn an_overlong_wobble_from_the_first_frame_names_both_cuts() {
    let mut run = Ride::new(600.0, 5.0, 0.0, 0.0, 0.0).run();
    for (t, steer) in run.t_s.iter().zip(&mut run.steer_deg) {
        // Above the quiet level from the first frame, growing at 0.6/s.
        let held = if *t < 500.0 {
            (0.6 * (0.6 * t).exp()).min(wobble::PEAK_DEG)
        } else {
            0.0
        };
        *steer = held * (TAU * wobble::FREQ_HZ * t).sin();
    }
    let (pieces, _) = episodes(&run, 6000);
    let first = pieces.first().expect("the growth is measured");
    assert_eq!(
        (first.cut_at_start, first.cut_at_end),
        (Some(Cut::DataStart), Some(Cut::Overlong)),
        "{first:?}"
    );
    assert!((first.sigma_per_s - 0.6).abs() < 0.15, "{first:?}");
}

/// Half an hour of frames, analysed with a window of 6000 frames, never
/// holds more than four windows.
#[test]
fn the_episode_search_holds_a_bounded_window() {
    let mut search = EpisodeSearch::with_chunk(FS_HZ, 6000);
    for i in 0..180_000 {
        let t = f64::from(i) / FS_HZ;
        search.push(t, (TAU * 7.0 * t).sin(), 5.0);
    }
    assert!(search.most_held() <= 24_000, "{}", search.most_held());
}

fn roll(run: &Run, chunk: usize) -> Vec<f64> {
    let mut out = Vec::new();
    let mut stream = RollStream::with_chunk(run.sample_rate_hz(), chunk);
    let mut keep = |frames: &Run, j: usize, r: f64| out.push((frames.t_s[j], r));
    for i in 0..run.len() {
        stream.push(run, i, &mut keep);
    }
    stream.finish(&mut keep);
    assert!(out.iter().zip(&run.t_s).all(|(o, t)| o.0 == *t));
    out.into_iter().map(|o| o.1).collect()
}

/// The backward pass run over chunks gives the roll of one pass over the
/// whole ride, to far below the sensor's resolution.
#[test]
fn roll_does_not_depend_on_the_chunk() {
    let mut run = Ride::new(600.0, 5.0, 15.0, 2.0, 1.0).run();
    // A gap: the estimate restarts on each side of it.
    let keep: Vec<usize> = (0..run.len())
        .filter(|&i| !(20_000..20_050).contains(&i))
        .collect();
    let mut gapped = Run::default();
    for i in keep {
        gapped.push_from(&run, i);
    }
    run = gapped;
    let whole = roll(&run, WHOLE);
    assert_eq!(whole.len(), run.len());
    for chunk in [700, 16_384] {
        let chunked = roll(&run, chunk);
        let worst = whole
            .iter()
            .zip(&chunked)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-9, "chunk {chunk}: {worst} deg");
    }
}

/// Frames at 100 Hz from `t0_s` for `len_s`: quiet, then a 7 Hz wobble
/// growing at 5/s from 0.05 degrees, 0.5 s in.
fn growing(t0_s: f64, len_s: f64) -> Vec<(f64, f64)> {
    let n = (len_s * FS_HZ).round() as usize;
    (0..n)
        .map(|i| {
            let u = i as f64 / FS_HZ;
            let amp = if u < 0.5 {
                0.0
            } else {
                0.05 * (5.0 * (u - 0.5)).exp()
            };
            (t0_s + u, amp * (TAU * 7.0 * u).sin())
        })
        .collect()
}

/// A stretch between gaps shorter than 2 s is too short to measure a mode
/// in: nothing is reported from it, where a longer one shows the wobble.
#[test]
fn stretches_under_two_seconds_are_not_analysed() {
    let found = |len_s: f64| {
        let mut search = EpisodeSearch::new(FS_HZ);
        for t0 in [0.0, 10.0, 20.0] {
            for (t, steer) in growing(t0, len_s) {
                search.push(t, steer, 5.0);
            }
        }
        search.finish(&Losses::default())
    };
    assert!(found(1.99).is_empty(), "{:#?}", found(1.99));
    // Exactly 2 s (200 frames) is long enough.
    for len_s in [2.0, 2.5] {
        let longer = found(len_s);
        for t0 in [0.0, 10.0, 20.0] {
            let within = |e: &Episode| (t0..t0 + len_s).contains(&e.onset_s);
            assert!(longer.iter().any(within), "{len_s} s: {longer:#?}");
        }
    }
}

/// Ten minutes at 3 m/s (the standard wobble at 14 s) with a kick every
/// 12 s from 29 s on (a 0.1 s push
/// of 4 degrees, then a 6.5 Hz ring of 1.5 degrees decaying at 0.8/s), over
/// small deterministic noise.
fn kicked_ride() -> Run {
    kicked_ride_of(600.0)
}

/// [`kicked_ride`] lasting `duration_s`.
fn kicked_ride_of(duration_s: f64) -> Run {
    let mut ride = Ride::new(duration_s, 3.0, 0.0, 0.5, 0.0);
    let mut state = 0x9E37_79B9u32;
    for (t, s) in ride.t_s.iter().zip(ride.steer_deg.iter_mut()) {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        *s += 0.02 * (f64::from(state) / f64::from(u32::MAX) - 0.5);
        let tau = (t - 29.0).rem_euclid(12.0);
        if *t < 20.0 {
            continue;
        }
        if tau < 0.1 {
            *s += 4.0 * (TAU / 0.2 * tau).sin();
        } else if tau < 11.0 {
            *s += 1.5 * (-0.8 * (tau - 0.1)).exp() * (TAU * 6.5 * (tau - 0.1)).sin();
        }
    }
    ride.run()
}

/// Kicks of `run` searched in pieces of `piece` frames, and the most
/// frames held.
fn kicks(run: &Run, piece: usize) -> (Vec<wobblog::analysis::Kick>, usize) {
    let mut search = KickSearch::with_piece(kicks::WOBBLE, run.sample_rate_hz(), 2.18, piece);
    for i in 0..run.len() {
        search.push(run.t_s[i], run.steer_deg[i], run.speed_mps[i]);
    }
    let held = search.most_held();
    (search.finish(), held)
}

/// The kick search holds at most a piece, and the pieces (overlapping by
/// 10 s) lose no kick at their edges and count none twice: every kick of
/// the ride is found once, as when the whole ride is searched at once.
#[test]
fn kicks_do_not_depend_on_the_piece() {
    let run = kicked_ride();
    let (whole, held) = kicks(&run, WHOLE);
    assert_eq!(held, run.len());
    // Kicks at 29 s, 41 s, ... up to the ride's end (601 s).
    let struck: Vec<f64> = (0..48).map(|k| 29.0 + 12.0 * f64::from(k)).collect();
    let times: Vec<f64> = whole.iter().map(|k| k.t_s).collect();
    assert_eq!(whole.len(), struck.len(), "{times:?}");
    for piece in [6000, 7919] {
        let (pieced, held) = kicks(&run, piece);
        assert!(held <= piece, "{held} frames held");
        assert_eq!(pieced.len(), struck.len(), "piece {piece}");
        for ((p, w), t) in pieced.iter().zip(&whole).zip(&struck) {
            assert!((p.t_s - t).abs() < 0.2, "{p:?}");
            assert!((p.t_s - w.t_s).abs() < 0.02, "{p:?} {w:?}");
            assert!((p.sigma_per_s - w.sigma_per_s).abs() < 0.02, "{p:?} {w:?}");
            assert!((p.sigma_per_s + 0.8).abs() < 0.1, "{p:?}");
        }
    }
}

/// Every kick rising before the search's settled time is among those it has
/// found, and none after: what the episode search is given as the frames go
/// by (`analysis::ride`) is final, across pieces and across a gap.
#[test]
fn kicks_found_before_the_settled_time_are_final() {
    let run = kicked_ride();
    // A 1 s gap at 300 s, between two kicks' rings.
    let kept: Vec<usize> = (0..run.len())
        .filter(|&i| !(300.0..301.0).contains(&run.t_s[i]))
        .collect();
    let mut search = KickSearch::with_piece(kicks::WOBBLE, run.sample_rate_hz(), 2.18, 6000);
    let mut seen = Vec::new();
    for &i in &kept {
        search.push(run.t_s[i], run.steer_deg[i], run.speed_mps[i]);
        if seen.last().is_none_or(|&(s, _)| s != search.settled_s()) {
            seen.push((search.settled_s(), search.found().to_vec()));
        }
    }
    let all = search.finish();
    // Pieces of 6000 frames (about 50 s each after the first) and the gap.
    assert!(seen.len() >= 10, "{} settled times", seen.len());
    assert!(
        seen.iter().any(|(s, _)| *s == 301.0),
        "the gap settles what lies before it"
    );
    for (settled_s, found) in &seen {
        let before: Vec<_> = all.iter().filter(|k| k.t_s < *settled_s).cloned().collect();
        assert_eq!(found, &before, "settled at {settled_s} s");
    }
}

/// A stable episode that is one of the host's kicks takes the kick's values
/// without a fit of its own: its fitted stretch is the kick's, to the
/// sample, and its frequency and growth rate are the kick's. The ride is
/// long enough (25 min) for the episode search to measure episodes before
/// the log ends, so frames must wait for the kicks.
#[test]
fn a_kicked_episode_is_the_kick_search_s_measurement() {
    let run = kicked_ride_of(1500.0);
    assert!(run.len() > 2 * wobblog::analysis::search::CHUNK_FRAMES);
    // The wheel of the default configuration, as the run has no other.
    let wheel_m = wobblog::cmd::detect::wheel_circumference_m(&[]).unwrap();
    let kicks = wobblog::analysis::find_kicks(&run, wheel_m);
    let ride = wobblog::analysis::ride::Ride::of(&run);
    let kicked: Vec<&Episode> = ride
        .episodes
        .iter()
        .filter(|e| e.stability == Stability::Stable)
        .collect();
    assert_eq!(kicked.len(), kicks.len(), "{:#?}", ride.episodes);
    for (e, k) in kicked.iter().zip(&kicks) {
        assert_eq!(e.fit_s, k.fit_s, "{e:?} {k:?}");
        assert_eq!(e.sigma_per_s, k.sigma_per_s);
        assert_eq!(e.freq_hz, k.freq_hz);
        assert_eq!(e.sigma_sd_per_s, Some(k.sigma_sd_per_s));
        assert_eq!(e.source.as_str(), "host");
    }
}
