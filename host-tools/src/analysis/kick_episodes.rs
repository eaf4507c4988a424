//! One kick, one sigma: a stable episode that is a kick takes the kick's
//! frequency, growth rate and uncertainty as `wobblog margin` takes them
//! (the host's re-measurement of the ring-down, [`super::kicks`], or the
//! card's record where the host found none: [`combine`] with
//! [`Prefer::Best`], margin's default), so that `wobble`, the data set's
//! episodes and the model's comparison and fit give a kick the sigma
//! `margin` gives it.
//!
//! Why the kick's values and not the episode's own: the episode's fit
//! starts at the largest swing, within the push and the band-pass's answer
//! to it, and stops at three times the background; the kick's skips the
//! push, fits the whole ring down to twice the background beside the
//! wheel's harmonic, and states a calibrated uncertainty. On the simulated
//! campaigns the kick's is the accurate one (`host-tools/docs/kick-testing.md`).
//! An unstable episode, and a stable one that holds no kick margin uses,
//! keep their own fit ([`Measured::Episode`]).

use super::campaign_kicks::{combine, CampaignKick, Prefer, MATCH_S};
use super::episodes::{Measured, Stability};
use super::kicks::Kick;
use super::Episode;
use wobble_core::format::KickRingDown;

/// Gives each stable episode of `episodes` (in time order) that holds a
/// kick of the log the kick's values: the host's measurements `host` and
/// the card's `records`, paired as `wobblog margin` pairs them.
pub fn give_kick_values(episodes: &mut [Episode], host: Vec<Kick>, records: &[KickRingDown]) {
    // A card record without a speed is one margin keeps when the run has
    // frames in the 2 s after it, as it has within an episode; the speed is
    // not what an episode takes (it keeps its speed at onset).
    let within = |t_s: f64| {
        episodes
            .iter()
            .find(|e| (e.onset_s - MATCH_S..=e.end_s).contains(&t_s))
            .map(|e| e.speed_at_onset_mps)
    };
    let kicks = combine(host, records, Prefer::Best, within);
    let mut taken = vec![false; kicks.len()];
    for episode in episodes
        .iter_mut()
        .filter(|e| e.stability == Stability::Stable)
    {
        if let Some(i) = kick_of(episode, &kicks, &taken) {
            taken[i] = true;
            let kick = &kicks[i];
            episode.freq_hz = kick.freq_hz;
            episode.sigma_per_s = kick.sigma_per_s;
            episode.sigma_sd_per_s = Some(kick.sigma_sd_per_s);
            episode.source = Measured::Kick(kick.source);
        }
    }
}

/// The kick (index into `kicks`, not yet `taken`) a stable episode is: of
/// those struck from [`MATCH_S`] before its onset to [`MATCH_S`] after its
/// own fit starts (its largest swing), the last one.
fn kick_of(episode: &Episode, kicks: &[CampaignKick], taken: &[bool]) -> Option<usize> {
    let struck = episode.onset_s - MATCH_S..=episode.fit_s[0] + MATCH_S;
    (0..kicks.len())
        .filter(|&i| !taken[i] && struck.contains(&kicks[i].t_s))
        .max_by(|&a, &b| kicks[a].t_s.total_cmp(&kicks[b].t_s))
}
