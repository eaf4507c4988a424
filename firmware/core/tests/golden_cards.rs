//! Golden cards: committed `.WBL` files written by the encoder of format
//! 1.0, decoded to the records `firmware/FORMAT.md` describes. A round trip
//! through one codec cannot see a change made to the encoder and the
//! decoder alike (two fields swapped, a delta re-based); these files can:
//! a format change must keep decoding them, or bump the major version on
//! purpose.
//!
//! Each card has a listing beside it (`NAME.txt`): every block's header,
//! every record with its file offset, then what the decoder reports. The
//! listings were checked by hand against FORMAT.md when the cards were
//! written; `raw_bytes_sit_where_format_md_puts_them` reads fields straight
//! from the bytes, without the decoder. To write the cards again (only on
//! purpose, with a version bump):
//! `WOBBLE_WRITE_GOLDEN=1 cargo test -p wobble-core --test golden_cards`.

use std::fmt::Write as _;
use std::path::PathBuf;

use wobble_core::format::block::{BlockHeader, HEADER_LEN};
use wobble_core::format::header::header_records;
use wobble_core::format::*;

/// The names of the cards, each a situation FORMAT.md describes.
const CARDS: [&str; 9] = [
    "clean",
    "dropout",
    "powercut",
    "timejump",
    "repeated",
    "gps",
    "alert",
    "marker",
    "aheadfill",
];

fn golden_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

/// A frame whose fields all differ, so a swap of any two shows.
fn frame(i: u64, t_us: u64) -> Record<'static> {
    let i16_of = |v: u64| v as i16;
    Record::Frame(Frame {
        t_us,
        accel: [i16_of(i), -i16_of(2 * i), 2048],
        gyro: [3, -4, i16_of(5 * i)],
        steer_cdeg: i16_of(100 * i) - 700,
        wheel_count: (i / 3) as u16,
        wheel_edge_age_us: if i < 2 { EDGE_AGE_NONE } else { 1234 },
        speed_mm_s: 4000 + i as u16,
        status: FrameStatus(if i.is_multiple_of(7) {
            FrameStatus::GPS_STALE
        } else {
            0
        }),
    })
}

/// Frames `from..to`, every 10 ms from `t0_us`.
fn frames(from: u64, to: u64, t0_us: u64) -> impl Iterator<Item = Record<'static>> {
    (from..to).map(move |i| frame(i, t0_us + (i - from) * 10_000))
}

/// The header every card opens with: log info, the channels, two config lines.
fn header() -> Vec<Record<'static>> {
    let info = LogInfo {
        t_us: 0,
        firmware: "golden-1.0",
        device_id: *b"GOLDEN-CARD!",
        sample_rate_hz: 100,
        run: 42,
    };
    header_records(info, ["sample_rate_hz=100", "wheel.circumference_m=2.1"]).collect()
}

/// Encodes `records` into sealed blocks, in file order.
fn blocks(records: impl IntoIterator<Item = Record<'static>>) -> Vec<Block> {
    let mut enc = BlockEncoder::new();
    let mut out = Vec::new();
    for r in records {
        if let Some(b) = enc.push(&r).unwrap() {
            out.push(*b);
        }
    }
    out.extend(enc.finish().copied());
    out
}

/// The bytes of card `name`, as today's encoder writes them.
fn card(name: &str) -> Vec<u8> {
    let mut records = header();
    let file: Vec<Block> = match name {
        "clean" => {
            records.extend(frames(0, 50, 20_000));
            blocks(records)
        }
        "dropout" => {
            // 30 frames, 40 dropped by a stalled card, then frames resume
            // where the lost ones end: no time jump.
            records.extend(frames(0, 30, 20_000));
            records.push(Record::Dropout(Dropout {
                t_us: 320_000,
                frames_lost: 40,
                reason: DropoutReason::QueueFull,
            }));
            records.extend(frames(70, 90, 720_000));
            blocks(records)
        }
        "powercut" => {
            // The power went while the last block was being rewritten in
            // place: half of the fuller version over the older flush.
            records.extend(frames(0, 30, 20_000));
            let mut enc = BlockEncoder::new();
            let mut out = Vec::new();
            for r in &records {
                out.extend(enc.push(r).unwrap().copied());
            }
            let flushed = *enc.snapshot().unwrap();
            for r in frames(30, 35, 320_000) {
                out.extend(enc.push(&r).unwrap().copied());
            }
            let mut torn = *enc.snapshot().unwrap();
            torn[256..].copy_from_slice(&flushed[256..]);
            out.push(torn);
            out
        }
        "aheadfill" => {
            // Blocks of zeros after the data: space reserved ahead of it
            // (FORMAT.md, "Unwritten space").
            records.extend(frames(0, 30, 20_000));
            let mut out = blocks(records);
            out.extend([[0; BLOCK_LEN]; 3]);
            out
        }
        "timejump" => {
            // 5 s of silence no dropout explains, then a frame before the
            // previous one (a clock restarted).
            records.extend(frames(0, 20, 20_000));
            records.extend(frames(20, 30, 5_210_000));
            records.extend(frames(30, 35, 1_000_000));
            blocks(records)
        }
        "repeated" => {
            // Block 1 written again after block 2 (a card that re-sent it).
            records.extend(frames(0, 60, 20_000));
            let mut b = blocks(records);
            let copy = b[1];
            b.insert(3, copy);
            b
        }
        "gps" => {
            records.extend(frames(0, 10, 20_000));
            records.push(Record::Gps(GpsFix {
                t_us: 105_000,
                utc: Some(UtcTime {
                    days_since_2000: 9_500,
                    ms_of_day: 45_296_789,
                }),
                lat_e7: Some(521_234_567),
                lon_e7: Some(-12_345_678),
                speed_cm_s: Some(456),
                course_cdeg: Some(27_050),
                alt_cm: Some(-1_234),
                fix: FixMode::Fix3d,
                sats: Some(11),
                hdop_d: Some(9),
            }));
            records.push(Record::UtcSync(UtcSync {
                t_us: 110_000,
                unix_ms: 1_767_225_600_000,
            }));
            records.extend(frames(10, 15, 120_000));
            blocks(records)
        }
        "alert" => {
            records.extend(frames(0, 10, 20_000));
            records.push(Record::Alert(Alert {
                t_us: 115_000,
                on: true,
                freq_chz: 640,
                amp_cdeg: 1_250,
            }));
            records.extend(frames(10, 20, 120_000));
            records.push(Record::Alert(Alert {
                t_us: 215_000,
                on: false,
                freq_chz: 0,
                amp_cdeg: 0,
            }));
            records.extend(frames(20, 22, 220_000));
            blocks(records)
        }
        "marker" => {
            records.extend(frames(0, 10, 20_000));
            records.push(Record::Marker(Marker {
                t_us: 118_000,
                id: 3,
            }));
            records.push(Record::Fault(Fault {
                t_us: 119_000,
                source: FaultSource::Gps,
                code: 1,
                count: 2,
            }));
            records.extend(frames(10, 12, 120_000));
            blocks(records)
        }
        other => panic!("no card {other}"),
    };
    file.concat()
}

/// The listing of a card: blocks and records with their offsets, read
/// block by block, then the decoder's events other than records, and its
/// totals.
fn listing(file: &[u8]) -> String {
    let mut out = String::new();
    for (i, chunk) in file.chunks(BLOCK_LEN).enumerate() {
        let at = i * BLOCK_LEN;
        let Ok(block) = <&Block>::try_from(chunk) else {
            writeln!(out, "@{at}: {} bytes, not a block", chunk.len()).unwrap();
            continue;
        };
        let header = match BlockHeader::parse(block) {
            Ok(h) => h,
            Err(e) => {
                writeln!(out, "@{at}: not a valid block: {e:?}").unwrap();
                continue;
            }
        };
        writeln!(out, "@{at}: {header:?}").unwrap();
        let mut records = Records::new(header.payload(block), header.t0_us);
        loop {
            let offset = at + HEADER_LEN + records.offset();
            let Some(record) = records.next() else { break };
            writeln!(out, "  @{offset}: {record:?}").unwrap();
        }
    }
    writeln!(out, "decoder:").unwrap();
    let mut dec = Decoder::new();
    dec.feed(file, true, &mut |e| {
        if !matches!(e, Event::Record(_)) {
            writeln!(out, "  {e:?}").unwrap();
        }
    });
    writeln!(out, "  {:?}", dec.stats()).unwrap();
    out
}

#[test]
fn golden_cards_decode_to_their_listings() {
    let write = std::env::var_os("WOBBLE_WRITE_GOLDEN").is_some();
    for name in CARDS {
        let wbl = golden_dir().join(format!("{name}.WBL"));
        let txt = golden_dir().join(format!("{name}.txt"));
        if write {
            std::fs::create_dir_all(golden_dir()).unwrap();
            let bytes = card(name);
            std::fs::write(&wbl, &bytes).unwrap();
            std::fs::write(&txt, listing(&bytes)).unwrap();
        }
        let bytes = std::fs::read(&wbl).unwrap();
        let expected = std::fs::read_to_string(&txt).unwrap();
        assert_eq!(listing(&bytes), expected, "{name}.WBL");
    }
}

#[test]
fn todays_encoder_still_writes_cards_that_decode_to_the_same_records() {
    // The encoder may pack differently one day (a new minor version): the
    // records it writes must still be the golden ones.
    for name in CARDS {
        let committed = std::fs::read(golden_dir().join(format!("{name}.WBL"))).unwrap();
        let records = |file: &[u8]| {
            let mut out = Vec::new();
            let mut dec = Decoder::new();
            dec.feed(file, true, &mut |e| out.push(format!("{e:?}")));
            out
        };
        assert_eq!(records(&card(name)), records(&committed), "{name}");
    }
}

/// CRC-32/ISO-HDLC bit by bit, independent of the `crc` crate.
fn crc32_bitwise(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

fn u16_at(b: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([b[at], b[at + 1]])
}

fn i16_at(b: &[u8], at: usize) -> i16 {
    u16_at(b, at) as i16
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

#[test]
fn raw_bytes_sit_where_format_md_puts_them() {
    let file = std::fs::read(golden_dir().join("clean.WBL")).unwrap();
    assert_eq!(file.len() % BLOCK_LEN, 0);
    for (seq, block) in file.chunks(BLOCK_LEN).enumerate() {
        assert_eq!(&block[0..4], b"WBLK");
        assert_eq!((block[4], block[5]), (1, 0), "version 1.0");
        assert!(u16_at(block, 6) <= 484);
        assert_eq!(u32_at(block, 8), seq as u32, "block seq at its offset");
        assert_eq!(u32_at(block, 508), crc32_bitwise(&block[..508]));
    }
    // Block 0: the log info first, time delta 0, then its fields.
    let b = &file[..BLOCK_LEN];
    assert_eq!(u32_at(b, 12), 0, "no frames before block 0");
    assert_eq!(&b[16..24], &[0; 8], "t0 = 0");
    assert_eq!(b[24], 0x80, "log info tag");
    let len = usize::from(b[25]);
    assert_eq!(b[26], 0, "zigzag(0)");
    assert_eq!(u16_at(b, 27), 100, "sample rate");
    assert_eq!(u32_at(b, 29), 42, "run");
    assert_eq!(&b[33..45], b"GOLDEN-CARD!");
    assert_eq!(&b[45..26 + len], b"golden-1.0");
    // Then the first channel: index 0, counts per unit, name length, name, unit.
    let ch = 26 + len;
    assert_eq!(b[ch], 0x81);
    assert_eq!(b[ch + 3], 0, "channel index");
    let scale = f32::from_le_bytes(b[ch + 4..ch + 8].try_into().unwrap());
    assert_eq!(scale, 2048.0, "ax counts per g");
    assert_eq!(b[ch + 8], 2);
    assert_eq!(&b[ch + 9..ch + 12], b"axg");

    // The first frame record in the file, found by its tag after the header
    // records (each sized record skipped by its length byte).
    let (block, at) = first_frame(&file);
    let b = &file[block * BLOCK_LEN..(block + 1) * BLOCK_LEN];
    assert_eq!(block, 0, "the header leaves room for frames in block 0");
    // Δ = 20 000 µs from the cursor at t0 = 0 (the log info's time):
    // zigzag(20 000 - 10 000) = 20 000, LEB128 in three bytes.
    assert_eq!(&b[at + 1..at + 4], &[0xA0, 0x9C, 0x01]);
    let f = at + 4;
    let fields: Vec<i16> = (0..7).map(|k| i16_at(b, f + 2 * k)).collect();
    assert_eq!(
        fields,
        [0, 0, 2048, 3, -4, 0, -700],
        "ax ay az gx gy gz steer"
    );
    assert_eq!(u16_at(b, f + 14), 0, "wheel_count");
    assert_eq!(u16_at(b, f + 16), 0xFFFF, "wheel_edge_age: none");
    assert_eq!(u16_at(b, f + 18), 4000, "speed mm/s");
    assert_eq!(b[f + 20], FrameStatus::GPS_STALE, "status");
    // The next frame, 10 ms later: one time byte, zigzag(0) = 0.
    let next = f + 21;
    assert_eq!((b[next], b[next + 1]), (0x01, 0x00));
    assert_eq!(i16_at(b, next + 2), 1, "ax of frame 1");
    assert_eq!(i16_at(b, next + 4), -2, "ay of frame 1");
    assert_eq!(i16_at(b, next + 12), 5, "gz of frame 1");
    assert_eq!(i16_at(b, next + 14), -600, "steer of frame 1");
}

/// Block index and in-block offset of the first frame record of `file`.
fn first_frame(file: &[u8]) -> (usize, usize) {
    for (i, b) in file.chunks(BLOCK_LEN).enumerate() {
        let end = 24 + usize::from(u16_at(b, 6));
        let mut at = 24;
        while at < end {
            match b[at] {
                0x01 => return (i, at),
                tag if tag >= 0x80 => at += 2 + usize::from(b[at + 1]),
                tag => panic!("fixed record 0x{tag:02x} before any frame"),
            }
        }
    }
    panic!("no frame");
}
