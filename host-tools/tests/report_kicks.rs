//! The report takes a campaign's kicks from its own reading of each log
//! (the analysis's kick search, the drawing pass's speeds) instead of a
//! pass of `margin`'s: the kicks and the answer must be `margin`'s, card
//! records without a speed included.

mod analysis_support;

use std::path::{Path, PathBuf};

use analysis_support::{kick_pass, kick_record, write_log, Extras};
use wobblog::analysis::campaign_kicks::{
    load_campaign_kicks, ride_campaign_kicks, Prefer, Source, SpeedsAfter,
};
use wobblog::analysis::margin::{Trend, RIDE_MARGIN};
use wobblog::analysis::run::read_rows;
use wobblog::analysis::Ride;
use wobblog::cmd::margin;
use wobblog::report::Campaign;

/// Kick passes from 2 to 3.5 m/s of a bicycle that wobbles at 4 m/s; the
/// second pass's card also recorded its kick (with its speed) and two
/// knocks the host does not see, one without a speed.
fn campaign(dir: &Path) -> Vec<PathBuf> {
    (0..4)
        .map(|i| {
            let log = dir.join(format!("RUN{:05}.WBL", i + 1));
            let extras = Extras {
                records: if i == 1 {
                    vec![
                        kick_record(3.05, Some(2500)),
                        kick_record(6.0, None),
                        kick_record(8.5, Some(2400)),
                    ]
                } else {
                    Vec::new()
                },
                ..Extras::default()
            };
            write_log(
                &log,
                &kick_pass(2.0 + 0.5 * f64::from(i), 4.0, 6.5, i),
                &extras,
            );
            log
        })
        .collect()
}

/// The kicks of `log` as the report takes them: its analysis, and the
/// speeds after its card records gathered from a second reading.
fn report_kicks(
    log: &Path,
    prefer: Prefer,
) -> Vec<wobblog::analysis::campaign_kicks::CampaignKick> {
    let ride = Ride::load(log).unwrap();
    let mut speeds = SpeedsAfter::for_records(&ride.summary.kick_records);
    read_rows(log, |_| {}, |row| speeds.push(row.t_s, row.speed_mps)).unwrap();
    ride_campaign_kicks(&ride, prefer, &speeds).unwrap()
}

#[test]
fn a_rides_kicks_are_margins() {
    let dir = tempfile::tempdir().unwrap();
    let logs = campaign(dir.path());
    for log in &logs {
        for prefer in [Prefer::Best, Prefer::Card, Prefer::Host] {
            let (_, want) = load_campaign_kicks(log, prefer).unwrap();
            assert_eq!(
                report_kicks(log, prefer),
                want,
                "{}: {prefer:?}",
                log.display()
            );
        }
    }
    // The card's records, the one without a speed among them, are used.
    let kicks = report_kicks(&logs[1], Prefer::Best);
    let sources: Vec<Source> = kicks.iter().map(|k| k.source).collect();
    assert_eq!(
        sources,
        [Source::CardHost, Source::Card, Source::Card],
        "{kicks:?}"
    );
    // The pass runs at 2.5 m/s throughout: the 2 s after 6 s too.
    assert!((kicks[1].speed_mps - 2.5).abs() < 1e-9, "{:?}", kicks[1]);
}

#[test]
fn the_reports_answer_is_margins() {
    let dir = tempfile::tempdir().unwrap();
    let logs = campaign(dir.path());
    let page = Campaign::load(&logs, None).unwrap();
    let (want, _, read) =
        margin::campaign(&logs, Prefer::Best, Trend::Line, RIDE_MARGIN, None, &[]).unwrap();
    read.unwrap();
    assert_eq!(
        serde_json::to_value(&page.margin).unwrap(),
        serde_json::to_value(&want).unwrap()
    );
    assert_eq!(
        want.kicks.len(),
        6,
        "four passes' kicks and two card records"
    );
    let counted: usize = page.rides.iter().map(|r| page.kicks_of(r)).sum();
    assert_eq!(counted, 6);
}
