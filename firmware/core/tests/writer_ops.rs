//! The writer's card operations per iteration (`app::writer`), counted by
//! the logger's counting device (`logger::ops`) on FAT32 cards: the queue
//! is sized for the worst iteration (`channels::WRITER_OPS_PER_ITERATION`),
//! so no iteration of a long ride may make more, whatever the cluster size.

mod card_support;
use card_support::{fat32_image, fill_card, header, ride, FRAME_PERIOD_US};

use core::future::Future;
use core::pin::pin;
use core::task::{Context, Poll, Waker};

use embassy_time::{Duration, MockDriver};
use embedded_sdmmc::{Block, BlockCount, BlockDevice, BlockIdx};
use wobble_core::app::writer;
use wobble_core::channels::{
    iteration_stall_us, RecordQueue, SharedStatus, WORST_ITERATION_US, WRITER_OPS_PER_ITERATION,
};
use wobble_core::format::{Decoder, Event, Record};
use wobble_core::logger::mock::{MockCard, MockError};
use wobble_core::logger::{CardLogger, CardOps, FixedTime, LoggerConfig, LoggerState};

const CARD_BYTES: u64 = 40 << 20;
const CONFIG: [&str; 1] = ["sample_rate_hz=100"];

/// Card operations of each writer iteration (a poll, a block of zeros
/// ahead, then one record's push, as `writer::run` does with no backlog) while a file is open on the card `image`,
/// and the blocks written.
fn iterations(image: Vec<u8>, frames: u64) -> (Vec<CardOps>, u32) {
    let mut log = CardLogger::new(
        MockCard::new(image),
        FixedTime::EPOCH,
        header(&CONFIG),
        LoggerConfig::DEFAULT,
    );
    let mut out = Vec::new();
    for (t, rec) in ride(frames) {
        let logging = matches!(log.state(), LoggerState::Logging { .. });
        let before = log.card_ops();
        log.poll(t);
        // The writer keeps up: the queue is empty before each record.
        log.write_ahead(t);
        log.push(&rec, t);
        if logging {
            out.push(log.card_ops().since(before));
        }
    }
    assert_eq!(log.state(), LoggerState::Logging { run: 1 });
    assert_eq!(log.stats().frames_lost, 0);
    (out, log.stats().blocks_written)
}

/// The most operations of any of `its`, and the slowest by the SD
/// specification.
fn worst(its: &[CardOps]) -> (u32, CardOps) {
    let most = its.iter().map(|o| o.total()).max().unwrap_or(0);
    let slow = its
        .iter()
        .copied()
        .max_by_key(|&o| iteration_stall_us(o))
        .unwrap_or_default();
    (most, slow)
}

/// Cards with clusters of one block (a FAT update at every block written)
/// to 4 KiB, empty and too full for the zeros the logger writes ahead: no
/// iteration makes more operations, or takes longer by the SD
/// specification's limits, than the queue is sized for, and with the zeros
/// ahead none makes more than 10. The one iteration that finds the card
/// full searches the whole FAT for a free cluster: a stall the queue is not
/// sized for (see `channels`).
/// Larger clusters need a card image too large for a test (65 525
/// clusters at least); they allocate less often and cost less.
#[test]
fn no_writer_iteration_exceeds_the_queue_sizing() {
    let (mut most_ops, mut slowest) = (0, CardOps::default());
    for cluster in [512, 1024, 4096] {
        // Ten minutes of ride: thousands of blocks, 1200 flushes.
        let (its, blocks) = iterations(fat32_image(CARD_BYTES, cluster), 60_000);
        let (ahead_most, _) = worst(&its);
        assert!(ahead_most <= 10, "cluster {cluster}: {ahead_most}");
        // Room for the ride and 16 KiB more: the zeros ahead stop about
        // 20 s before the end, and every block then extends the file.
        let mut full = fat32_image(CARD_BYTES, cluster);
        fill_card(&mut full, (u64::from(blocks) + 32) * 512);
        let (mut full_its, _) = iterations(full, 60_000);
        // Where the zeros ahead find the card full, embedded-sdmmc has
        // searched the whole FAT for a free cluster (as a full card's last
        // block always made it): a stall outside the sizing, once.
        let searches = full_its.iter().filter(|o| o.reads > 10).count();
        assert!(searches <= 1, "cluster {cluster}: {searches}");
        full_its.retain(|o| o.reads <= 10);
        for (card, its) in [("empty", &its), ("nearly full", &full_its)] {
            let (most, slow) = worst(its);
            let busy = its.iter().filter(|o| o.total() > 0).count();
            println!(
                "cluster {cluster} B, {card}: {} iterations, {busy} with card operations, at \
                 most {most} operations in one; slowest by the specification {slow:?}: {} ms",
                its.len(),
                iteration_stall_us(slow) / 1000
            );
            assert!(
                most <= WRITER_OPS_PER_ITERATION,
                "cluster {cluster}, {card}: an iteration made {most} card operations"
            );
            assert!(
                iteration_stall_us(slow) <= WORST_ITERATION_US,
                "cluster {cluster}, {card}: {slow:?}"
            );
            // Most iterations only encode: a block closes every dozen
            // records, and a block of zeros goes ahead about as often.
            assert!(busy * 4 < its.len());
            most_ops = most_ops.max(most);
            if iteration_stall_us(slow) > iteration_stall_us(slowest) {
                slowest = slow;
            }
        }
    }
    // The sizing keeps the bound measured before the zeros ahead: loose
    // by a few operations now, never short.
    assert!(most_ops >= 10, "{most_ops}");
    assert!(iteration_stall_us(slowest) >= 3_000_000, "{slowest:?}");
}

/// Polls `future` to its end, advancing the mock clock by 1 ms whenever it
/// waits (the writer's idle timer).
fn drive<F: Future>(future: F) -> F::Output {
    let mut future = pin!(future);
    let mut cx = Context::from_waker(Waker::noop());
    loop {
        if let Poll::Ready(out) = future.as_mut().poll(&mut cx) {
            return out;
        }
        MockDriver::get().advance(Duration::from_millis(1));
    }
}

/// The real writer loop counts its iterations' operations into the shared
/// status: the boot's opening of the card apart from the ride's iterations,
/// which stay within the sizing.
#[test]
fn the_writer_task_reports_its_worst_iterations() {
    let queue = RecordQueue::new();
    let shared = SharedStatus::new();
    let mut log = CardLogger::new(
        MockCard::new(fat32_image(CARD_BYTES, 512)),
        FixedTime::EPOCH,
        header(&CONFIG),
        LoggerConfig::DEFAULT,
    );
    let mut records = ride(3_000).map(|(_, r)| r).peekable();
    let producer = async {
        // 300 records at a time, the mock clock moving 10 ms per frame.
        while records.peek().is_some() {
            for rec in records.by_ref().take(300) {
                if matches!(rec, Record::Frame(_)) {
                    MockDriver::get().advance(Duration::from_micros(FRAME_PERIOD_US));
                }
                assert!(queue.push(rec));
            }
            while !queue.is_empty() {
                embassy_futures::yield_now().await;
            }
        }
        shared.request_stop();
    };
    let (closed, ()) = drive(embassy_futures::join::join(
        writer::run(&mut log, &queue, &shared),
        producer,
    ));
    closed.expect("closed");
    let figures = shared.writer();
    println!("{figures:?}");
    // Opening: the MBR, boot sector, FSInfo, the root directory's search
    // for the next run number, the file's creation, the header and a flush.
    assert!(figures.open_ops_max > figures.ops_max);
    // At least one flush with a block to write, and never past the sizing.
    assert!(figures.ops_max >= 5);
    assert!(figures.ops_max <= WRITER_OPS_PER_ITERATION);
    assert_eq!(log.stats().frames_lost, 0);
    assert_eq!(log.stats().frames_on_card, 3_000);
}

/// A card whose writes are counted outside the logger.
struct Watched<'a> {
    card: MockCard,
    writes: &'a core::cell::Cell<u32>,
}

impl BlockDevice for Watched<'_> {
    type Error = MockError;

    fn read(&self, blocks: &mut [Block], start: BlockIdx) -> Result<(), MockError> {
        self.card.read(blocks, start)
    }

    fn write(&self, blocks: &[Block], start: BlockIdx) -> Result<(), MockError> {
        self.writes.set(self.writes.get() + 1);
        self.card.write(blocks, start)
    }

    fn num_blocks(&self) -> Result<BlockCount, MockError> {
        self.card.num_blocks()
    }
}

/// Frames in a log file, and the frames its dropout records count.
fn frames_in(file: &[u8]) -> (u32, u32) {
    let (mut frames, mut dropped) = (0, 0);
    Decoder::new().feed(file, true, &mut |e| match e {
        Event::Record(Record::Frame(_)) => frames += 1,
        Event::Record(Record::Dropout(d)) => dropped += d.frames_lost,
        _ => {}
    });
    (frames, dropped)
}

/// The supply falls below the power-fail threshold mid-ride: the writer
/// closes the file at once (every frame it had is on the card, in a file
/// closed cleanly), writes nothing to the card while the supply stays low,
/// and opens a new file when it is back; the frames the queue could not
/// hold meanwhile are counted in the new file's dropout record.
#[test]
fn a_failing_supply_closes_the_file_and_leaves_the_card_alone() {
    let queue = RecordQueue::new();
    let shared = SharedStatus::new();
    let writes = core::cell::Cell::new(0);
    let card = Watched {
        card: MockCard::new(fat32_image(CARD_BYTES, 512)),
        writes: &writes,
    };
    let mut log = CardLogger::new(
        card,
        FixedTime::EPOCH,
        header(&CONFIG),
        LoggerConfig::DEFAULT,
    );
    let records: Vec<Record<'static>> = ride(3_000).map(|(_, r)| r).collect();
    let mut frames_before = 0;
    let mut writes_while_low = (0, 0);
    let producer = async {
        let settle = || async {
            for _ in 0..20 {
                MockDriver::get().advance(Duration::from_millis(10));
                embassy_futures::yield_now().await;
            }
        };
        let mut frames = 0;
        for (k, rec) in records.iter().enumerate() {
            if k == 2_000 {
                while !queue.is_empty() {
                    embassy_futures::yield_now().await;
                }
                frames_before = frames;
                shared.set_power_low(true);
                settle().await;
                let closed_at = writes.get();
                settle().await;
                writes_while_low = (closed_at, writes.get());
            }
            if k == 2_800 {
                shared.set_power_low(false);
            }
            if matches!(rec, Record::Frame(_)) {
                MockDriver::get().advance(Duration::from_micros(FRAME_PERIOD_US));
                frames += 1;
            }
            // While the supply is low the queue fills, then drops.
            let _ = queue.push(*rec);
            while !shared.power_low() && !queue.is_empty() {
                embassy_futures::yield_now().await;
            }
        }
        shared.request_stop();
    };
    let (closed, ()) = drive(embassy_futures::join::join(
        writer::run(&mut log, &queue, &shared),
        producer,
    ));
    closed.expect("the second file closed");
    assert_eq!(shared.power_falls(), 1);
    assert_eq!(
        writes_while_low.0, writes_while_low.1,
        "card writes while low"
    );
    let image = log.into_device().card.image();
    let first = card_support::read_file(&image, "RUN00001.WBL").expect("first file");
    let second = card_support::read_file(&image, "RUN00002.WBL").expect("second file");
    let (first_frames, first_dropped) = frames_in(&first);
    let (second_frames, dropped) = frames_in(&second);
    // Every frame before the fall is in the first file, closed cleanly.
    assert_eq!((first_frames, first_dropped), (frames_before, 0));
    // Every frame after it is in the second file or counted dropped.
    assert!(dropped > 0);
    assert_eq!(first_frames + second_frames + dropped, 3_000);
}
