//! The logger on the real card adapter with each kind of card a rider can
//! buy, inserted by the person at the bench when a test asks (within 60 s):
//! an exFAT card is an unusable card (fault 4, its own LED pattern), never a
//! missing one; a full FAT32 card is a full card; a FAT16 card and a FAT32
//! card log, and the self-test counts their free space in their FAT. The
//! cards are bench cards: the logger writes a run file on each that logs.
//! How to make each card: `firmware/docs/board.md`, "Cards".
#![no_std]
#![no_main]

use defmt_rtt as _;

#[cfg(test)]
#[embedded_test::tests]
mod tests {
    use embassy_time::{Duration, Instant};
    use embedded_sdmmc::BlockDevice;
    use wobble_core::logger::{CardLogger, FixedTime, HeaderSpec, LoggerConfig, LoggerState};
    use wobble_core::selftest::fat_free_mib;
    use wobble_on_target::{poll_until, sd_card as sd};

    /// How long the person at the bench has to insert the card asked for.
    const INSERT: Duration = Duration::from_secs(60);
    /// How often the card is tried meanwhile (as a rider's swap is retried).
    const RETRY: Duration = Duration::from_millis(200);

    const HEADER: HeaderSpec<'static> = HeaderSpec {
        firmware: "on-target card_formats",
        device_id: [0; 12],
        sample_rate_hz: 100,
        config: &[],
    };

    /// Asks for `card`, then polls a logger on the adapter (a retry every
    /// 200 ms, as a rider's swap is retried) until its state is `want`;
    /// fails at the deadline, or at once on a state in `never`.
    async fn logger_reaches(
        card: &str,
        want: fn(LoggerState) -> bool,
        never: fn(LoggerState) -> bool,
    ) {
        let config = LoggerConfig {
            flush_period_ms: 500,
            retry_period_ms: 200,
        };
        let mut logger = CardLogger::new(sd(), FixedTime::EPOCH, HEADER, config);
        defmt::info!("insert {} ({} s)", card, INSERT.as_secs());
        let reached = poll_until(INSERT, RETRY, || {
            logger.poll(Instant::now().as_micros());
            let state = logger.state();
            defmt::assert!(!never(state), "{}: the logger says {}", card, state);
            want(state).then_some(state)
        })
        .await;
        match reached {
            Some(state) => defmt::info!("{}: {}", card, state),
            None => defmt::panic!(
                "{}: the logger says {} at the deadline",
                card,
                logger.state()
            ),
        }
    }

    /// Asks for `card` and waits until it answers with a FAT volume; its
    /// free space as the self-test counts it, MiB.
    async fn free_space_of(card: &str) -> u32 {
        let sd = sd();
        defmt::info!("insert {} ({} s)", card, INSERT.as_secs());
        let free = poll_until(INSERT, RETRY, || {
            sd.num_blocks().ok().and_then(|_| fat_free_mib(&sd))
        })
        .await;
        let free = defmt::unwrap!(free, "{}: no FAT volume answered", card);
        defmt::info!("{}: {} MiB free", card, free);
        free
    }

    #[test]
    #[timeout(90)]
    async fn an_exfat_card_is_an_unusable_card_not_a_missing_one() {
        logger_reaches(
            "an exFAT card (any SDXC card as sold)",
            |s| s == LoggerState::UnusableCard,
            |s| matches!(s, LoggerState::Logging { .. } | LoggerState::CardFull),
        )
        .await;
    }

    #[test]
    #[timeout(90)]
    async fn a_full_fat32_card_is_a_full_card() {
        logger_reaches(
            "a full FAT32 card",
            |s| s == LoggerState::CardFull,
            |s| matches!(s, LoggerState::Logging { .. } | LoggerState::UnusableCard),
        )
        .await;
    }

    #[test]
    #[timeout(90)]
    async fn a_fat16_card_logs() {
        logger_reaches(
            "a FAT16 card (2 GB or less)",
            |s| matches!(s, LoggerState::Logging { .. }),
            |s| matches!(s, LoggerState::UnusableCard | LoggerState::CardFull),
        )
        .await;
    }

    #[test]
    #[timeout(90)]
    async fn free_space_is_counted_on_a_fat16_card() {
        defmt::assert!(free_space_of("a FAT16 card (2 GB or less)").await > 0);
    }

    #[test]
    #[timeout(90)]
    async fn a_full_card_has_no_free_space() {
        defmt::assert_eq!(free_space_of("a full FAT32 card").await, 0);
    }
}
