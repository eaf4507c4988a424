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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::campaign_kicks::tests::record;
    use crate::analysis::campaign_kicks::{card_sd, Source};

    /// An episode from `onset_s` to `end_s` whose own fit (sigma -3 1/s,
    /// 7 Hz) starts at `fit_from_s`.
    fn episode(stability: Stability, onset_s: f64, fit_from_s: f64, end_s: f64) -> Episode {
        Episode {
            mode: crate::analysis::KickMode::Wobble,
            onset_s,
            end_s,
            peak_s: fit_from_s,
            freq_hz: 7.0,
            sigma_per_s: -3.0,
            sigma_sd_per_s: None,
            source: Measured::Episode,
            peak_amp_deg: 1.0,
            speed_at_onset_mps: 3.0,
            stability,
            fit_s: [fit_from_s, end_s - 0.5],
            censored: false,
            cut_at_start: None,
            cut_at_end: None,
        }
    }

    /// A host kick rising at `t_s` with sigma `sigma`.
    fn host(t_s: f64, sigma: f64) -> Kick {
        Kick {
            t_s,
            speed_mps: 3.1,
            freq_hz: 6.4,
            sigma_per_s: sigma,
            sigma_sd_per_s: 0.04,
            sigma_se_fit_per_s: 0.01,
            amp_deg: 1.0,
            fit_s: [t_s + 0.5, t_s + 4.0],
            residual_rel: 0.1,
        }
    }

    #[test]
    fn a_stable_episode_struck_by_a_kick_takes_the_kicks_values() {
        let mut episodes = vec![
            episode(Stability::Stable, 10.0, 10.3, 15.0),
            episode(Stability::Unstable, 20.0, 20.5, 25.0),
        ];
        give_kick_values(&mut episodes, vec![host(9.6, -0.4), host(21.0, -0.5)], &[]);
        let kick = &episodes[0];
        assert_eq!(
            (kick.freq_hz, kick.sigma_per_s, kick.sigma_sd_per_s),
            (6.4, -0.4, Some(0.04))
        );
        assert_eq!(kick.source, Measured::Kick(Source::Host));
        assert_eq!(kick.source.as_str(), "host");
        // Its own times and speed stay.
        assert_eq!((kick.onset_s, kick.speed_at_onset_mps), (10.0, 3.0));
        // A growing wobble is no kick, whatever lies in it.
        assert_eq!(episodes[1], episode(Stability::Unstable, 20.0, 20.5, 25.0));
        assert_eq!(episodes[1].source.as_str(), "episode");
    }

    #[test]
    fn a_kick_outside_the_strike_leaves_the_episode_its_own_fit() {
        // Too early (over 0.5 s before the onset), and too late (over
        // 0.5 s after its own fit starts: a knock during the ring-down).
        for t in [9.45, 10.85] {
            let mut episodes = vec![episode(Stability::Stable, 10.0, 10.3, 15.0)];
            give_kick_values(&mut episodes, vec![host(t, -0.4)], &[]);
            assert_eq!(episodes[0].source, Measured::Episode, "{t}");
            assert_eq!(episodes[0].sigma_per_s, -3.0);
        }
        let mut episodes = vec![episode(Stability::Stable, 10.0, 10.3, 15.0)];
        give_kick_values(&mut episodes, vec![host(10.75, -0.4)], &[]);
        assert_eq!(episodes[0].sigma_per_s, -0.4);
    }

    #[test]
    fn of_two_kicks_the_episode_is_the_last_struck_before_its_fit() {
        let mut episodes = vec![episode(Stability::Stable, 10.0, 10.9, 15.0)];
        give_kick_values(
            &mut episodes,
            vec![host(10.0, -0.4), host(10.8, -0.6), host(11.5, -0.7)],
            &[],
        );
        assert_eq!(episodes[0].sigma_per_s, -0.6);
    }

    #[test]
    fn a_card_record_gives_its_values_where_the_host_found_no_kick() {
        let mut episodes = vec![
            episode(Stability::Stable, 10.0, 10.3, 15.0),
            episode(Stability::Stable, 20.0, 20.3, 25.0),
        ];
        // The card saw both kicks, the host only the second (and a record
        // without a speed is still a kick within an episode).
        let records = [record(9.8, None), record(19.9, Some(3000))];
        give_kick_values(&mut episodes, vec![host(20.1, -0.5)], &records);
        let card = &episodes[0];
        assert_eq!(card.source.as_str(), "card");
        assert!((card.freq_hz - 6.9).abs() < 1e-6 && card.sigma_per_s == -1.1);
        assert_eq!(card.sigma_sd_per_s, Some(card_sd(0.05)));
        let both = &episodes[1];
        assert_eq!(both.source.as_str(), "card-host");
        assert_eq!((both.sigma_per_s, both.sigma_sd_per_s), (-0.5, Some(0.04)));
    }
}
