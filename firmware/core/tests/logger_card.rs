//! The SD logger against an in-memory FAT32 card: file naming, header,
//! whole-block writes, flushing, power cuts, missing, removed and full cards.

mod card_support;
use card_support::{fat32_image, fill_card, header, read_file, with_fs};

use embedded_sdmmc::{Mode, VolumeIdx, VolumeManager};
use proptest::prelude::*;
use wobble_core::format::{
    Decoder, Dropout, DropoutReason, Event, FaultSource, Frame, FrameStatus, Record,
};
use wobble_core::logger::mock::MockCard;
use wobble_core::logger::{
    CardLogger, FixedTime, LoggerConfig, LoggerState, FAULT_CARD_ABSENT, FAULT_CARD_FORMAT,
    FAULT_CARD_FULL, FAULT_CARD_WRITE,
};

/// Smallest comfortable FAT32 volume with 512-byte clusters (65 525 needed).
const CARD_BYTES: u64 = 40 << 20;
const FRAME_PERIOD_US: u64 = 10_000;
const CONFIG: [&str; 2] = ["sample_rate_hz=100", "flush_period_ms=500"];

type Logger = CardLogger<'static, MockCard, FixedTime>;

fn logger(card: MockCard) -> Logger {
    CardLogger::new(
        card,
        FixedTime::EPOCH,
        header(&CONFIG),
        LoggerConfig::DEFAULT,
    )
}

#[derive(Debug, Default)]
struct Decoded {
    frames: Vec<u64>,
    dropouts: Vec<Dropout>,
    card_faults: Vec<(u8, u16)>,
    configs: Vec<String>,
    first_is_info: bool,
    damaged: u64,
}

fn decode(data: &[u8]) -> Decoded {
    let mut out = Decoded::default();
    let mut first = true;
    let mut decoder = Decoder::new();
    decoder.feed(data, true, &mut |ev| {
        if let Event::Record(rec) = ev {
            if first {
                out.first_is_info = matches!(rec, Record::LogInfo(_));
                first = false;
            }
            match rec {
                Record::Frame(f) => out.frames.push(f.t_us),
                Record::Dropout(d) => out.dropouts.push(d),
                Record::Fault(f) if f.source == FaultSource::Card => {
                    out.card_faults.push((f.code, f.count));
                }
                Record::Config(c) => out.configs.push(c.text.to_string()),
                _ => {}
            }
        }
    });
    out.damaged = decoder.stats().damaged_blocks;
    out
}

fn frame(i: u64) -> Record<'static> {
    Record::Frame(Frame {
        t_us: i * FRAME_PERIOD_US,
        accel: [i as i16, 2, 2048],
        gyro: [1, 2, 3],
        steer_cdeg: (i % 300) as i16,
        wheel_count: i as u16,
        wheel_edge_age_us: 100,
        speed_mm_s: 4000,
        status: FrameStatus(0),
    })
}

/// Pushes frames `from..to` at 100 Hz, polling the logger as the writer does.
fn run(log: &mut Logger, from: u64, to: u64) {
    for i in from..to {
        let now = i * FRAME_PERIOD_US;
        log.poll(now);
        log.push(&frame(i), now);
    }
}

#[test]
fn fresh_card_gets_run_one_with_header_then_every_frame() {
    let mut log = logger(MockCard::new(fat32_image(CARD_BYTES, 512)));
    run(&mut log, 0, 3000);
    assert_eq!(log.state(), LoggerState::Logging { run: 1 });
    log.close(3000 * FRAME_PERIOD_US).expect("close");
    let image = log.with_device(|c| c.image());
    let data = read_file(&image, "RUN00001.WBL").expect("file");
    assert_eq!(data.len() % 512, 0);
    let d = decode(&data);
    assert!(d.first_is_info);
    assert_eq!(d.configs, CONFIG);
    let expected: Vec<u64> = (0..3000).map(|i| i * FRAME_PERIOD_US).collect();
    assert_eq!(d.frames, expected);
    assert!(d.dropouts.is_empty() && d.card_faults.is_empty());
    assert_eq!(log.stats().frames_lost, 0);
}

#[test]
fn a_closed_log_reads_back_through_a_new_file_system_on_the_same_card() {
    let mut log = logger(MockCard::new(fat32_image(CARD_BYTES, 512)));
    run(&mut log, 0, 700);
    log.close(700 * FRAME_PERIOD_US).expect("close");
    assert_eq!(log.stats().frames_on_card, 700);
    let volumes = VolumeManager::new(log.into_device(), FixedTime::EPOCH);
    let volume = volumes.open_volume(VolumeIdx(0)).expect("volume");
    let root = volume.open_root_dir().expect("root");
    let file = root
        .open_file_in_dir("RUN00001.WBL", Mode::ReadOnly)
        .expect("log file");
    let mut data = vec![0u8; file.length() as usize];
    let mut read = 0;
    while read < data.len() {
        read += file.read(&mut data[read..]).expect("read");
    }
    let d = decode(&data);
    assert!(d.first_is_info);
    let expected: Vec<u64> = (0..700).map(|i| i * FRAME_PERIOD_US).collect();
    assert_eq!(d.frames, expected);
}

#[test]
fn each_power_on_takes_the_next_free_run_number() {
    let mut image = fat32_image(CARD_BYTES, 512);
    for run_no in 1..=3 {
        let mut log = logger(MockCard::new(image));
        run(&mut log, 0, 10);
        assert_eq!(log.state(), LoggerState::Logging { run: run_no });
        log.close(100_000).expect("close");
        image = log.with_device(|c| c.image());
    }
    for name in ["RUN00001.WBL", "RUN00002.WBL", "RUN00003.WBL"] {
        assert_eq!(
            decode(&read_file(&image, name).expect(name)).frames.len(),
            10
        );
    }
}

#[test]
fn flushes_keep_the_file_size_within_one_flush_period() {
    let mut log = logger(MockCard::new(fat32_image(CARD_BYTES, 512)));
    // No close: what a reader sees at any moment is what the last flush said.
    let mut start = 0;
    for end in [130u64, 777, 1500] {
        run(&mut log, start, end);
        start = end;
        let image = log.with_device(|c| c.image());
        let on_card = decode(&read_file(&image, "RUN00001.WBL").expect("file"))
            .frames
            .len() as u64;
        let period_frames = u64::from(LoggerConfig::DEFAULT.flush_period_ms) / 10;
        assert!(
            end - on_card <= period_frames,
            "{on_card} of {end} frames on card"
        );
        assert_eq!(on_card, u64::from(log.stats().frames_on_card));
        // ...and no more often than that: each flush costs block writes.
        let periods = end / period_frames;
        let flushes = u64::from(log.stats().flushes);
        assert!(
            (periods..=periods + 1).contains(&flushes),
            "{flushes} flushes in {periods} flush periods"
        );
    }
}

#[test]
fn card_absent_at_boot_is_reported_with_the_exact_loss() {
    let card = MockCard::new(fat32_image(CARD_BYTES, 512));
    card.set_removed(true);
    let mut log = logger(card);
    run(&mut log, 0, 350);
    assert_eq!(log.state(), LoggerState::NoCard);
    log.with_device(|c| c.set_removed(false));
    run(&mut log, 350, 600);
    log.close(600 * FRAME_PERIOD_US).expect("close");
    let image = log.with_device(|c| c.image());
    let d = decode(&read_file(&image, "RUN00001.WBL").expect("file"));
    // Attempts at 0, 1, 2, 3 s failed; the one at 4 s found the card.
    assert_eq!(d.card_faults, [(FAULT_CARD_ABSENT, 4)]);
    assert_eq!(d.dropouts.len(), 1);
    assert_eq!(d.dropouts[0].reason, DropoutReason::CardUnavailable);
    assert_eq!(d.dropouts[0].frames_lost, 400);
    assert_eq!(d.frames.len(), 200);
    assert_eq!(d.frames[0], 400 * FRAME_PERIOD_US);
}

/// A card as an SDXC card ships: an MBR whose first partition is exFAT
/// (type 0x07), its boot sector `EXFAT   ` (which embedded-sdmmc cannot
/// read).
fn exfat_image() -> Vec<u8> {
    let mut image = vec![0u8; 1 << 20];
    let entry = &mut image[446..462];
    entry[4] = 0x07;
    entry[8..12].copy_from_slice(&1u32.to_le_bytes());
    entry[12..16].copy_from_slice(&2047u32.to_le_bytes());
    image[510] = 0x55;
    image[511] = 0xAA;
    image[512 + 3..512 + 11].copy_from_slice(b"EXFAT   ");
    image[1022] = 0x55;
    image[1023] = 0xAA;
    image
}

/// An exFAT card is not a missing card: the logger says the card is
/// unusable (its own fault code and state, so the LED and the self-test can
/// tell the rider to format it), never writes to it, and once the card is
/// formatted FAT32 logs with the attempts and the frames lost meanwhile on
/// record. A GPT card (protective MBR, type 0xEE) and a card without an MBR
/// are unusable too.
#[test]
fn an_exfat_card_is_unusable_not_absent_and_never_written() {
    let card = MockCard::new(exfat_image());
    let mut log = logger(card);
    run(&mut log, 0, 350);
    assert_eq!(log.state(), LoggerState::UnusableCard);
    assert_eq!(log.stats().faults[usize::from(FAULT_CARD_FORMAT) - 1], 4);
    assert_eq!(log.stats().faults[usize::from(FAULT_CARD_ABSENT) - 1], 0);
    log.with_device(|c| {
        assert_eq!(c.writes(), 0);
        assert_eq!(c.image(), exfat_image());
        c.set_image(fat32_image(CARD_BYTES, 512));
    });
    run(&mut log, 350, 600);
    assert_eq!(log.state(), LoggerState::Logging { run: 1 });
    log.close(600 * FRAME_PERIOD_US).expect("close");
    let image = log.with_device(|c| c.image());
    let d = decode(&read_file(&image, "RUN00001.WBL").expect("file"));
    assert_eq!(d.card_faults, [(FAULT_CARD_FORMAT, 4)]);
    assert_eq!(d.dropouts[0].reason, DropoutReason::CardUnavailable);
    assert_eq!(d.dropouts[0].frames_lost, 400);

    let mut gpt = exfat_image();
    gpt[446 + 4] = 0xEE;
    let mut bare = exfat_image();
    bare[510] = 0;
    for image in [gpt, bare] {
        let mut log = logger(MockCard::new(image));
        run(&mut log, 0, 10);
        assert_eq!(log.state(), LoggerState::UnusableCard);
    }
    // A card pulled out is still a missing card.
    let card = MockCard::new(exfat_image());
    card.set_removed(true);
    let mut log = logger(card);
    run(&mut log, 0, 10);
    assert_eq!(log.state(), LoggerState::NoCard);
}

#[test]
fn queue_dropouts_while_the_card_is_absent_join_the_count() {
    // The queue dropped 37 frames while the writer was busy with a card
    // that then went away: its dropout record must not vanish with them.
    let card = MockCard::new(fat32_image(CARD_BYTES, 512));
    card.set_removed(true);
    let mut log = logger(card);
    run(&mut log, 0, 100);
    let dropout = Record::Dropout(Dropout {
        t_us: 100 * FRAME_PERIOD_US,
        frames_lost: 37,
        reason: DropoutReason::QueueFull,
    });
    log.push(&dropout, 137 * FRAME_PERIOD_US);
    run(&mut log, 137, 150);
    assert_eq!(log.stats().frames_lost, 100 + 37 + 13);
    log.with_device(|c| c.set_removed(false));
    run(&mut log, 150, 300);
    log.close(300 * FRAME_PERIOD_US).expect("close");
    let image = log.with_device(|c| c.image());
    let d = decode(&read_file(&image, "RUN00001.WBL").expect("file"));
    let lost: u32 = d.dropouts.iter().map(|x| x.frames_lost).sum();
    assert_eq!(d.frames.len() as u32 + lost, 300, "{:?}", d.dropouts);
}

#[test]
fn card_pulled_mid_run_loses_only_what_was_not_on_it() {
    let mut log = logger(MockCard::new(fat32_image(CARD_BYTES, 512)));
    run(&mut log, 0, 1234);
    log.with_device(|c| c.set_removed(true));
    run(&mut log, 1234, 1700);
    assert_eq!(log.state(), LoggerState::NoCard);
    log.with_device(|c| c.set_removed(false));
    run(&mut log, 1700, 2500);
    assert_eq!(log.state(), LoggerState::Logging { run: 2 });
    log.close(2500 * FRAME_PERIOD_US).expect("close");
    let image = log.with_device(|c| c.image());
    let first = decode(&read_file(&image, "RUN00001.WBL").expect("run 1"));
    let second = decode(&read_file(&image, "RUN00002.WBL").expect("run 2"));
    // One failed write, then failed attempts at 1, 2, 3 and 4 s after it.
    assert_eq!(
        second.card_faults,
        [(FAULT_CARD_ABSENT, 4), (FAULT_CARD_WRITE, 1)]
    );
    assert_eq!(second.dropouts.len(), 1);
    let lost = u64::from(second.dropouts[0].frames_lost);
    // Every frame is either on the card or counted, never both.
    let on_card = (first.frames.len() + second.frames.len()) as u64;
    assert_eq!(on_card + lost, 2500);
    assert!(first
        .frames
        .windows(2)
        .all(|w| w[1] == w[0] + FRAME_PERIOD_US));
    assert_eq!(
        *first.frames.last().expect("frames") / FRAME_PERIOD_US + 1,
        first.frames.len() as u64
    );
    assert_eq!(
        second.frames[0] / FRAME_PERIOD_US,
        first.frames.len() as u64 + lost
    );
}

#[test]
fn full_card_keeps_logging_and_counts_the_loss() {
    let mut image = fat32_image(CARD_BYTES, 512);
    fill_card(&mut image, 16 * 1024);
    let mut log = logger(MockCard::new(image));
    run(&mut log, 0, 2000);
    // Shown as full, not as missing (the LED's own pattern).
    assert_eq!(log.state(), LoggerState::CardFull);
    let stats = log.stats();
    assert!(stats.faults[usize::from(FAULT_CARD_FULL) - 1] >= 1);
    let image = log.with_device(|c| c.image());
    let d = decode(&read_file(&image, "RUN00001.WBL").expect("file"));
    assert_eq!(d.frames.len() as u64 + u64::from(stats.frames_lost), 2000);
    assert_eq!(d.damaged, 0);
    // Retries on the full card leave no empty files behind.
    let names: Vec<String> = with_fs(&mut image.clone(), |fs| {
        fs.root_dir()
            .iter()
            .filter_map(Result::ok)
            .map(|e| e.file_name())
            .collect()
    });
    assert_eq!(
        names.iter().filter(|n| n.starts_with("RUN")).count(),
        1,
        "{names:?}"
    );
}

/// A card whose run numbers are used up (`RUN99999.WBL` is there) is a full
/// card, not a missing one: each attempt to open it counts as the full-card
/// fault, and every frame meanwhile as lost; a full card is tried again
/// only every `FULL_RETRY_PERIODS` retry periods (each attempt walks the
/// FAT), and a card that has room again is logged to.
#[test]
fn a_card_out_of_run_numbers_counts_as_full() {
    let mut image = fat32_image(CARD_BYTES, 512);
    with_fs(&mut image, |fs| {
        fs.root_dir().create_file("RUN99999.WBL").expect("create");
    });
    let mut log = logger(MockCard::new(image));
    // Attempts at 0, 10 and 20 s (a retry period of 1 s, ten of them).
    let periods = wobble_core::logger::FULL_RETRY_PERIODS;
    assert_eq!(periods, 10);
    run(&mut log, 0, 2500);
    assert_eq!(log.state(), LoggerState::CardFull);
    let stats = log.stats();
    assert_eq!(
        (
            stats.faults[usize::from(FAULT_CARD_FULL) - 1],
            stats.faults[usize::from(FAULT_CARD_ABSENT) - 1]
        ),
        (3, 0)
    );
    assert_eq!(stats.frames_lost, 2500);
    // Emptied (the last run deleted): logging again at the next attempt.
    log.with_device(|c| {
        let mut image = c.image();
        with_fs(&mut image, |fs| {
            fs.root_dir().remove("RUN99999.WBL").expect("remove")
        });
        c.set_image(image);
    });
    run(&mut log, 2500, 3100);
    assert_eq!(log.state(), LoggerState::Logging { run: 1 });
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// A power cut at any block write keeps every frame of the last flush,
    /// loses at most one flush period, and never damages a written block.
    #[test]
    fn power_cut_loses_at_most_one_flush_period(cut_after_writes in 1u32..400) {
        let card = MockCard::new(fat32_image(CARD_BYTES, 512));
        card.set_fuel(Some(cut_after_writes));
        let mut log = logger(card);
        let mut flushed_frames = 0u32;
        let mut cut_at = None;
        for i in 0..4000u64 {
            let now = i * FRAME_PERIOD_US;
            log.poll(now);
            log.push(&frame(i), now);
            // The card stops answering: shown as missing or, where a
            // failed FAT read leaves no free cluster found, as full.
            if !matches!(log.state(), LoggerState::Logging { .. }) {
                cut_at = Some(i + 1);
                break;
            }
            flushed_frames = log.stats().frames_on_card;
        }
        let cut_at = cut_at.expect("the power cut happened");
        let image = log.with_device(|c| c.image());
        let data = read_file(&image, "RUN00001.WBL").unwrap_or_default();
        let d = decode(&data);
        prop_assert_eq!(d.damaged, 0);
        prop_assert!(d.frames.len() as u32 >= flushed_frames);
        let expected: Vec<u64> = (0..d.frames.len() as u64).map(|i| i * FRAME_PERIOD_US).collect();
        prop_assert_eq!(&d.frames, &expected);
        let period_frames = u64::from(LoggerConfig::DEFAULT.flush_period_ms) / 10;
        prop_assert!(cut_at - d.frames.len() as u64 <= period_frames + 1);
    }
}
