//! The analyses stream: episodes and the roll estimate of a run do not
//! depend on how many frames are held at once, and what is held stays
//! bounded however long the run.

mod analysis_support;

use std::f64::consts::TAU;

use analysis_support::{assert_same_episode as assert_same, wobble, Ride, FS_HZ};
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
