//! The margin prediction on a small, seeded sample of the stress
//! campaigns (`wobble_hil::margin_stress`; the full tables come from
//! `cargo run -p wobble-hil --release --example margin_stress`). Seeds
//! 5000 on: neither those the defaults were chosen on (0-399) nor those
//! of the published figures (1000000 on).

use wobble_hil::margin_stress::{campaign, host_outcomes, Recipe, Shape, Tally};
use wobblog::analysis::margin::{predict, BendPrior};

const FIRST: u64 = 5000;
const CAMPAIGNS: u64 = 40;

fn tally(shape: Shape) -> Tally {
    Tally::of(&host_outcomes(
        &Recipe::acceptance(shape),
        BendPrior::DEFAULT,
        FIRST,
        CAMPAIGNS,
    ))
}

/// The board's interval allows for the same bends as the host's.
#[test]
fn the_board_allows_for_the_hosts_bends() {
    use wobble_core::detector::margin as board;
    use wobblog::analysis::margin as host;
    assert_eq!(
        f64::from(board::BEND_SHAPE_SD_CONVEX),
        host::BEND_SHAPE_SD_CONVEX
    );
    assert_eq!(
        f64::from(board::BEND_SHAPE_SD_CONCAVE),
        host::BEND_SHAPE_SD_CONCAVE
    );
}

/// A bicycle stable above its kicks and less so below them: no wobble
/// speed is claimed ahead, no riding limit is made up, and the rise of
/// sigma towards the slowest kicks is said in most campaigns.
#[test]
fn no_wobble_speed_is_claimed_when_it_is_stable_above() {
    let t = tally(Shape::LowSpeedWobble);
    assert_eq!(t.false_claims, 0, "{t:?}");
    assert_eq!(t.estimates, 0, "{t:?}");
    let warned = (FIRST..FIRST + CAMPAIGNS)
        .filter(|&seed| {
            let c = campaign(&Recipe::acceptance(Shape::LowSpeedWobble), seed);
            let m = predict(&c.kicks);
            assert_eq!(m.advice.ride_below_mps, None, "{m:?}");
            m.warnings
                .iter()
                .any(|w| w.contains("rises towards lower speeds"))
        })
        .count();
    assert!(warned * 2 > CAMPAIGNS as usize, "{warned}");
}

/// On bicycles like ours (the prior's mean shape) and straight ones the
/// closed intervals hold the truth, and ours are closed often enough to
/// be of use; over the other shapes at most one lower bound in the 120
/// lies more than 10 % above the truth (convex bends beyond the prior do
/// it in about 1 % of campaigns) and no riding limit above it.
#[test]
fn the_lower_bound_and_the_closed_intervals_hold() {
    let ours = tally(Shape::OurModel);
    assert!(ours.closed * 3 >= ours.n, "{ours:?}");
    assert!(ours.coverage() >= 0.9, "{ours:?}");
    let straight = tally(Shape::Straight);
    assert!(straight.coverage() >= 0.9, "{straight:?}");
    let mut over_10 = 0;
    for shape in [Shape::Convex, Shape::Concave, Shape::FlatAtCrossing] {
        let t = tally(shape);
        over_10 += t.lower_over_10;
        assert_eq!(t.ride_over, 0, "{shape:?} {t:?}");
    }
    assert!(over_10 <= 1, "{over_10}");
}
