//! The second half of bench step 5b (`firmware/docs/board.md`): after the
//! supply was cut by a relay during logging, again and again, every run
//! file on the card decodes with the core's decoder. The first half is the
//! logger's own firmware riding through the cuts; this test only reads the
//! card afterwards, on a board powered up anew.
//!
//! Each `RUNnnnnn.WBL` must hold the log info first, naming its run; whole
//! blocks in order (none lost, none out of order; copies of a block are
//! counted, not errors); at most one torn stretch (the block the card was
//! programming when the power went: failing its CRC, garbled, or cut
//! short); no bad record, no impossible value, no time going backwards;
//! and its frames 10 ms apart, except where a dropout record or that torn
//! block explains a step. The zeros written ahead of the data
//! (`FORMAT.md`, "Unwritten space") are counted, not errors.
//!
//! Run: after the cuts, take the card out, power the board up with the
//! probe attached (so the logger does not open a new file on it), then
//! `cargo test -p wobble-on-target --target thumbv7em-none-eabihf --test
//! power_cut` and insert the card when asked (60 s).
#![no_std]
#![no_main]

use defmt_rtt as _;

#[cfg(test)]
#[embedded_test::tests]
mod tests {
    use core::fmt::Write;
    use core::ops::ControlFlow;

    use embassy_time::Duration;
    use embedded_sdmmc::{BlockDevice, Mode, VolumeIdx};
    use wobble_core::format::{DecodeStats, Event, Record, SkipCause};
    use wobble_core::logger::{self, parse_run, FixedTime};
    use wobble_on_target::{decode_file, poll_until, sd_card, FrameSpacing};

    /// Run files read at most (a card of ten cuts holds ten or so).
    const MAX_RUNS: usize = 128;

    /// What one run file holds, as the decoder reads it.
    #[derive(Default)]
    struct Run {
        records: u32,
        /// The first record is the log info naming this run.
        info_first: bool,
        /// The frames and those not 10 ms after the one before.
        spacing: FrameSpacing,
        dropouts: u32,
        /// Stretches skipped as a torn write leaves them: a block failing
        /// its CRC, bytes that are no block, a block cut short.
        torn: u32,
        /// Anything else that is not a record: a gap, an unreadable record,
        /// an impossible value, time going backwards, a bad header.
        anomalies: u32,
    }

    impl Run {
        fn see(&mut self, event: Event<'_>, run: u32) {
            let record = match event {
                Event::Record(record) => record,
                // Copies of a decoded block: their records were decoded once.
                Event::Skipped {
                    cause: SkipCause::Repeated,
                    ..
                } => return,
                Event::Skipped {
                    cause: SkipCause::Damaged | SkipCause::Garbage | SkipCause::TruncatedTail,
                    ..
                } => {
                    self.torn += 1;
                    return;
                }
                // A step forward is counted with the frames (`steps_off`).
                Event::TimeJump { from_us, to_us } if to_us > from_us => return,
                _ => {
                    self.anomalies += 1;
                    return;
                }
            };
            if self.records == 0 {
                self.info_first = matches!(record, Record::LogInfo(info) if info.run == run);
            }
            self.records += 1;
            match record {
                Record::Frame(frame) => self.spacing.see(frame.t_us),
                Record::Dropout(_) => self.dropouts += 1,
                _ => {}
            }
        }

        /// Whether the run survived its cut, with what the decoder counted.
        fn whole(&self, d: &DecodeStats) -> bool {
            self.info_first
                && d.blocks_lost == 0
                && d.out_of_order_blocks == d.repeated_blocks
                && d.damaged_blocks <= 1
                && self.torn <= 1
                && d.bad_records == 0
                && d.time_jumps == 0
                && self.spacing.steps_off <= self.dropouts + self.torn
                && self.anomalies == 0
        }
    }

    #[test]
    #[timeout(300)]
    async fn every_run_on_the_card_decodes_after_the_power_cuts() {
        let card = sd_card();
        defmt::info!("insert the card the power cuts were logged on (60 s)");
        let inserted = poll_until(Duration::from_secs(60), Duration::from_millis(200), || {
            card.num_blocks().ok()
        })
        .await;
        defmt::unwrap!(inserted, "no card answered");
        let volumes = logger::volumes(card, FixedTime::EPOCH);
        let volume = defmt::unwrap!(volumes.open_volume(VolumeIdx(0)).ok());
        let root = defmt::unwrap!(volume.open_root_dir().ok());
        let mut runs: heapless::Vec<u32, MAX_RUNS> = heapless::Vec::new();
        defmt::unwrap!(root
            .iterate_dir(|entry| {
                if let Some(run) = parse_run(&entry.name) {
                    if runs.push(run).is_err() {
                        return ControlFlow::Break(());
                    }
                }
                ControlFlow::Continue(())
            })
            .ok());
        runs.sort_unstable();
        defmt::info!("{} run files", runs.len());
        defmt::assert!(!runs.is_empty(), "no run file on the card");

        let mut broken = 0u32;
        for &run in &runs {
            let mut name: heapless::String<12> = heapless::String::new();
            defmt::unwrap!(write!(name, "RUN{run:05}.WBL").ok());
            let file = defmt::unwrap!(root.open_file_in_dir(name.as_str(), Mode::ReadOnly).ok());
            let mut seen = Run::default();
            let decoded = decode_file(&file, |event| seen.see(event, run));
            defmt::unwrap!(file.close().ok());
            let whole = seen.whole(&decoded);
            defmt::info!(
                "{}: {} frames, {} dropout records, {} frame steps off 10 ms, {} torn stretches, \
                 info first {}: {} -> {}",
                name.as_str(),
                seen.spacing.frames,
                seen.dropouts,
                seen.spacing.steps_off,
                seen.torn,
                seen.info_first,
                decoded,
                if whole { "whole" } else { "DAMAGED" }
            );
            if !whole {
                broken += 1;
            }
        }
        defmt::assert_eq!(broken, 0, "{} of {} runs damaged", broken, runs.len());
    }
}
