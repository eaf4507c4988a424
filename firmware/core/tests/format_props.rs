//! Property tests of the card format: round trips and recovery from damage.

use proptest::collection::vec;
use proptest::prelude::*;
use wobble_core::format::*;

/// An owned record, so strategies can generate header strings.
#[derive(Clone, Debug)]
enum Spec {
    Plain(Record<'static>),
    Info {
        t_us: u64,
        firmware: String,
        device_id: [u8; 12],
        rate: u16,
        run: u32,
    },
    Channel {
        t_us: u64,
        index: u8,
        name: String,
        unit: String,
        scale: f32,
    },
    Config {
        t_us: u64,
        text: String,
    },
}

impl Spec {
    fn record(&self) -> Record<'_> {
        match self {
            Spec::Plain(r) => *r,
            Spec::Info {
                t_us,
                firmware,
                device_id,
                rate,
                run,
            } => Record::LogInfo(LogInfo {
                t_us: *t_us,
                firmware,
                device_id: *device_id,
                sample_rate_hz: *rate,
                run: *run,
            }),
            Spec::Channel {
                t_us,
                index,
                name,
                unit,
                scale,
            } => Record::Channel(ChannelDef {
                t_us: *t_us,
                index: *index,
                name,
                unit,
                counts_per_unit: *scale,
            }),
            Spec::Config { t_us, text } => Record::Config(ConfigLine { t_us: *t_us, text }),
        }
    }
}

const T_MAX: u64 = 1 << 50;

fn frame() -> impl Strategy<Value = Frame> {
    (
        0..T_MAX,
        any::<[i16; 3]>(),
        any::<[i16; 3]>(),
        any::<i16>(),
        any::<[u16; 3]>(),
        any::<u8>(),
    )
        .prop_map(
            |(t_us, accel, gyro, steer_cdeg, [count, age, speed], status)| Frame {
                t_us,
                accel,
                gyro,
                steer_cdeg,
                wheel_count: count,
                wheel_edge_age_us: age,
                speed_mm_s: speed,
                status: FrameStatus(status),
            },
        )
}

fn gps() -> impl Strategy<Value = GpsFix> {
    let utc = (any::<u16>(), 0..86_401_000u32).prop_map(|(days_since_2000, ms_of_day)| UtcTime {
        days_since_2000,
        ms_of_day,
    });
    let pos = (any::<i32>(), any::<i32>());
    (
        0..T_MAX,
        proptest::option::of(utc),
        proptest::option::of(pos),
        proptest::option::of(any::<u16>()),
        proptest::option::of(any::<u16>()),
        proptest::option::of(any::<i32>()),
        prop_oneof![
            Just(FixMode::None),
            Just(FixMode::Fix2d),
            Just(FixMode::Fix3d)
        ],
        proptest::option::of(0..255u8),
        proptest::option::of(0..255u8),
    )
        .prop_map(
            |(t_us, utc, pos, speed, course, alt, fix, sats, hdop)| GpsFix {
                t_us,
                utc,
                lat_e7: pos.map(|p| p.0),
                lon_e7: pos.map(|p| p.1),
                speed_cm_s: speed,
                course_cdeg: course,
                alt_cm: alt,
                fix,
                sats,
                hdop_d: hdop,
            },
        )
}

fn plain() -> impl Strategy<Value = Record<'static>> {
    prop_oneof![
        8 => frame().prop_map(Record::Frame),
        2 => gps().prop_map(Record::Gps),
        1 => (0..T_MAX, any::<u64>()).prop_map(|(t_us, unix_ms)| Record::UtcSync(UtcSync { t_us, unix_ms })),
        1 => (0..T_MAX, any::<bool>(), any::<u16>(), any::<u16>()).prop_map(|(t_us, on, freq_chz, amp_cdeg)| {
            Record::Alert(Alert { t_us, on, freq_chz, amp_cdeg })
        }),
        1 => (0..T_MAX, any::<u16>()).prop_map(|(t_us, id)| Record::Marker(Marker { t_us, id })),
        1 => (0..T_MAX, any::<u32>(), any::<u8>()).prop_map(|(t_us, frames_lost, r)| {
            Record::Dropout(Dropout { t_us, frames_lost, reason: DropoutReason::from_code(r) })
        }),
        1 => (0..T_MAX, any::<u8>(), any::<u8>(), any::<u16>()).prop_map(|(t_us, s, code, count)| {
            Record::Fault(Fault { t_us, source: FaultSource::from_code(s), code, count })
        }),
    ]
}

fn spec() -> impl Strategy<Value = Spec> {
    prop_oneof![
        12 => plain().prop_map(Spec::Plain),
        1 => (0..T_MAX, ".{0,40}", any::<[u8; 12]>(), any::<u16>(), any::<u32>()).prop_map(
            |(t_us, firmware, device_id, rate, run)| Spec::Info { t_us, firmware, device_id, rate, run }
        ),
        1 => (0..T_MAX, any::<u8>(), "[a-z_]{0,20}", "[a-zA-Z/µ°]{0,8}", any::<f32>().prop_filter("NaN", |x| !x.is_nan()))
            .prop_map(|(t_us, index, name, unit, scale)| Spec::Channel { t_us, index, name, unit, scale }),
        1 => (0..T_MAX, "[ -~]{0,200}").prop_map(|(t_us, text)| Spec::Config { t_us, text }),
    ]
}

/// Frames at a steady 100 Hz with jitter, interleaved with other records
/// stamped near them: what a logger writes.
fn ride() -> impl Strategy<Value = Vec<Spec>> {
    (
        vec((spec(), -20_000i64..20_000, 9_000u64..11_000), 1..400),
        0..T_MAX / 2,
    )
        .prop_map(|(items, start)| {
            let mut t = start;
            items
                .into_iter()
                .map(|(mut s, offset, step)| {
                    if let Spec::Plain(Record::Frame(f)) = &mut s {
                        t += step;
                        f.t_us = t;
                    } else {
                        set_time(&mut s, t.saturating_add_signed(offset));
                    }
                    s
                })
                .collect()
        })
}

fn set_time(s: &mut Spec, t: u64) {
    match s {
        Spec::Plain(r) => match r {
            Record::Frame(x) => x.t_us = t,
            Record::Gps(x) => x.t_us = t,
            Record::UtcSync(x) => x.t_us = t,
            Record::Alert(x) => x.t_us = t,
            Record::Marker(x) => x.t_us = t,
            Record::Dropout(x) => x.t_us = t,
            Record::Fault(x) => x.t_us = t,
            _ => unreachable!("plain records only"),
        },
        Spec::Info { t_us, .. } | Spec::Channel { t_us, .. } | Spec::Config { t_us, .. } => {
            *t_us = t
        }
    }
}

/// Encodes the records; returns the file and each block's records.
fn encode(specs: &[Spec]) -> (Vec<u8>, Vec<Vec<Record<'_>>>) {
    let mut enc = BlockEncoder::new();
    let mut file = Vec::new();
    let mut blocks = vec![Vec::new()];
    for s in specs {
        let rec = s.record();
        if let Some(block) = enc.push(&rec).expect("encodable") {
            file.extend_from_slice(block);
            blocks.push(Vec::new());
        }
        blocks.last_mut().unwrap().push(rec);
    }
    if let Some(block) = enc.finish() {
        file.extend_from_slice(block);
    } else {
        blocks.pop();
    }
    (file, blocks)
}

fn decode(file: &[u8]) -> (Vec<Event<'_>>, DecodeStats) {
    let mut dec = Decoder::new();
    let mut events = Vec::new();
    dec.feed(file, true, &mut |e| events.push(e));
    (events, *dec.stats())
}

/// Decodes `file` fed in chunks of `chunk` bytes (at least a block), each
/// continuing where the decoder stopped consuming.
fn decode_in_chunks(file: &[u8], chunk: usize) -> (Vec<Event<'_>>, DecodeStats) {
    let mut dec = Decoder::new();
    let mut events = Vec::new();
    let mut start = 0;
    while start < file.len() {
        let end = (start + chunk.max(BLOCK_LEN)).min(file.len());
        start += dec.feed(&file[start..end], end == file.len(), &mut |e| {
            events.push(e)
        });
    }
    (events, *dec.stats())
}

fn records<'a>(events: &[Event<'a>]) -> Vec<Record<'a>> {
    events
        .iter()
        .filter_map(|e| {
            if let Event::Record(r) = e {
                Some(*r)
            } else {
                None
            }
        })
        .collect()
}

/// What the decoder passes on of records as written: values the firmware
/// cannot write are dropped, an impossible sample rate becomes the default.
fn sanitised<'a>(written: impl IntoIterator<Item = Record<'a>>) -> Vec<Record<'a>> {
    written
        .into_iter()
        .filter_map(|mut r| {
            match &mut r {
                Record::Gps(fix) => {
                    fix.drop_out_of_range();
                }
                Record::LogInfo(info) if !info.sample_rate_is_valid() => {
                    info.sample_rate_hz = limits::DEFAULT_SAMPLE_RATE_HZ;
                }
                Record::UtcSync(sync) if !sync.is_valid() => return None,
                _ => {}
            }
            Some(r)
        })
        .collect()
}

fn frames_in(block: &[Record<'_>]) -> u32 {
    block
        .iter()
        .filter(|r| matches!(r, Record::Frame(_)))
        .count() as u32
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn any_records_round_trip(specs in vec(spec(), 0..300)) {
        let (file, blocks) = encode(&specs);
        prop_assert_eq!(file.len() % BLOCK_LEN, 0);
        let (events, stats) = decode(&file);
        let expected = sanitised(blocks.concat());
        prop_assert_eq!(records(&events), expected);
        prop_assert_eq!(stats.blocks_lost + stats.bytes_skipped + stats.bad_records, 0);
    }

    #[test]
    fn decoding_in_chunks_equals_decoding_at_once(specs in ride(), chunk in 1usize..3000) {
        let (file, _) = encode(&specs);
        let (whole, _) = decode(&file);
        let (pieces, _) = decode_in_chunks(&file, chunk);
        prop_assert_eq!(records(&pieces), records(&whole));
    }

    /// Damage, garbage and a cut tail too: every event and every total is
    /// the same however the file is cut into chunks (one damaged stretch is
    /// one `Skipped`, even across a chunk's end).
    #[test]
    fn damaged_files_decode_the_same_in_any_chunks(
        specs in ride(),
        flips in vec((any::<prop::sample::Index>(), 0usize..BLOCK_LEN, 1u8..=255), 0..6),
        garbage in vec(any::<u8>(), 0..1500),
        garbage_at in any::<prop::sample::Index>(),
        cut in 0usize..BLOCK_LEN,
        chunk in 1usize..3000,
    ) {
        let (mut file, blocks) = encode(&specs);
        for (block, byte, mask) in &flips {
            file[block.index(blocks.len()) * BLOCK_LEN + byte] ^= mask;
        }
        let at = garbage_at.index(blocks.len() + 1) * BLOCK_LEN;
        file.splice(at..at, garbage);
        file.truncate(file.len() - cut.min(file.len()));
        let (whole, whole_stats) = decode(&file);
        let (pieces, stats) = decode_in_chunks(&file, chunk);
        prop_assert_eq!(&pieces, &whole);
        prop_assert_eq!(stats, whole_stats);
    }

    #[test]
    fn damage_loses_exactly_the_damaged_blocks(
        specs in ride(),
        flips in vec((any::<prop::sample::Index>(), 0usize..BLOCK_LEN, 1u8..=255), 0..6),
        cut in any::<prop::sample::Index>(),
        do_cut in any::<bool>(),
    ) {
        let (mut file, blocks) = encode(&specs);
        let n = blocks.len();
        let mut damaged = vec![false; n];
        for (block, byte, mask) in &flips {
            let b = block.index(n);
            file[b * BLOCK_LEN + byte] ^= mask;
            damaged[b] = true;
        }
        if do_cut {
            let at = cut.index(file.len() + 1);
            file.truncate(at);
            for (b, d) in damaged.iter_mut().enumerate() {
                *d |= (b + 1) * BLOCK_LEN > at;
            }
        }
        let (events, stats) = decode(&file);

        // Every undamaged block comes back exactly.
        let expected = sanitised(
            blocks.iter().zip(&damaged).filter(|(_, d)| !**d).flat_map(|(b, _)| b.clone()),
        );
        prop_assert_eq!(records(&events), expected);

        // Every run of damaged blocks followed by a good one is one gap of
        // exactly those blocks and frames. Damage at the end cannot be sized.
        let mut expected_gaps = Vec::new();
        let mut run: Option<(u32, u32, u32)> = None;
        for (b, block) in blocks.iter().enumerate() {
            if damaged[b] {
                let r = run.get_or_insert((b as u32, 0, 0));
                r.1 += 1;
                r.2 += frames_in(block);
            } else if let Some((first, count, frames)) = run.take() {
                expected_gaps.push((first, count, frames));
            }
        }
        let gaps: Vec<(u32, u32, u32)> = events
            .iter()
            .filter_map(|e| if let Event::Gap(g) = e { Some((g.first_seq, g.blocks, g.frames)) } else { None })
            .collect();
        prop_assert_eq!(&gaps, &expected_gaps);
        prop_assert_eq!(stats.blocks_lost, expected_gaps.iter().map(|g| u64::from(g.1)).sum::<u64>());
        prop_assert_eq!(stats.bytes_skipped as usize + BLOCK_LEN * damaged.iter().filter(|d| !**d).count(), file.len());
    }

    #[test]
    fn garbage_between_blocks_is_skipped(specs in ride(), junk in vec((any::<prop::sample::Index>(), vec(any::<u8>(), 1..700)), 0..5)) {
        let (file, blocks) = encode(&specs);
        let n = blocks.len();
        let mut inserts: Vec<(usize, Vec<u8>)> = junk.into_iter().map(|(i, j)| (i.index(n + 1), j)).collect();
        inserts.sort_by_key(|(i, _)| *i);
        let mut dirty = Vec::new();
        let mut junk_len = 0;
        for b in 0..=n {
            for (_, j) in inserts.iter().filter(|(i, _)| *i == b) {
                dirty.extend_from_slice(j);
                junk_len += j.len();
            }
            if b < n {
                dirty.extend_from_slice(&file[b * BLOCK_LEN..(b + 1) * BLOCK_LEN]);
            }
        }
        let (events, stats) = decode(&dirty);
        prop_assert_eq!(records(&events), sanitised(blocks.concat()));
        prop_assert_eq!(stats.bytes_skipped as usize, junk_len);
        prop_assert_eq!(stats.blocks_lost, 0);
    }

    #[test]
    fn arbitrary_bytes_never_panic(bytes in vec(any::<u8>(), 0..4000)) {
        let (_, stats) = decode(&bytes);
        prop_assert!(stats.bytes_skipped as usize <= bytes.len());
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// Blocks that pass every block check (magic, version, length, CRC)
    /// around arbitrary payloads: the record decoder itself meets garbage.
    /// Every block is taken as a block, nothing panics, and the decoder's
    /// record counts are exactly what the record decoder (`Records`) makes
    /// of each payload on its own: every payload reached it, whole.
    ///
    /// Why random bytes (`arbitrary_bytes_never_panic`) never got this far
    /// (`stats.blocks` 0): a block is only taken with its 4-byte magic, a
    /// known version, a payload length that fits and a CRC-32 over all 508
    /// bytes before it, so a random 512 bytes is a block with odds of about
    /// 2^-64. The same blocks with their CRC broken show it: none is taken,
    /// every byte is skipped as damage.
    #[test]
    fn sealed_blocks_of_garbage_reach_the_record_decoder(
        payloads in vec((vec(any::<u8>(), 0..=block::PAYLOAD_LEN), any::<u32>()), 1..6),
    ) {
        let mut file = Vec::new();
        for (seq, (payload, t0)) in payloads.iter().enumerate() {
            let mut b: Block = [0; BLOCK_LEN];
            b[block::HEADER_LEN..block::HEADER_LEN + payload.len()].copy_from_slice(payload);
            BlockHeader {
                version_minor: block::VERSION_MINOR,
                payload_len: payload.len() as u16,
                seq: seq as u32,
                first_frame: 0,
                t0_us: u64::from(*t0),
            }
            .seal(&mut b);
            file.extend_from_slice(&b);
        }
        let (events, stats) = decode(&file);
        prop_assert_eq!(stats.blocks, payloads.len() as u64);
        prop_assert_eq!((stats.damaged_blocks, stats.bytes_skipped), (0, 0));
        let (mut good, mut bad, mut unknown) = (0u64, 0u64, 0u64);
        for (payload, t0) in &payloads {
            let mut recs = Records::new(payload, u64::from(*t0));
            for r in recs.by_ref() {
                match r {
                    Ok(_) => good += 1,
                    Err(_) => bad += 1,
                }
            }
            unknown += u64::from(recs.skipped_unknown());
        }
        prop_assert_eq!(
            (stats.records, stats.bad_records, stats.unknown_records),
            (good, bad, unknown)
        );
        // A non-empty payload always yields something to count.
        let non_empty = payloads.iter().filter(|p| !p.0.is_empty()).count() as u64;
        prop_assert!(good + bad + unknown >= non_empty, "{:?}", stats);
        prop_assert!(records(&events).len() as u64 <= stats.records);

        // The same blocks with a CRC bit flipped: no block, all skipped.
        for b in file.chunks_mut(BLOCK_LEN) {
            b[BLOCK_LEN - 1] ^= 1;
        }
        let (_, broken) = decode(&file);
        prop_assert_eq!(broken.blocks, 0);
        prop_assert_eq!(broken.records + broken.bad_records, 0);
        prop_assert_eq!(broken.bytes_skipped, file.len() as u64);
    }

    /// Real blocks with a byte of their payload changed and the CRC made
    /// valid again (a writer's bug, not the card's): the other blocks come
    /// back exactly, and the changed one decodes as far as it can.
    #[test]
    fn a_resealed_damaged_payload_spoils_only_its_block(
        specs in ride(),
        which in any::<prop::sample::Index>(),
        at in any::<prop::sample::Index>(),
        mask in 1u8..=255,
    ) {
        let (mut file, blocks) = encode(&specs);
        let b = which.index(blocks.len());
        let block: &mut Block = (&mut file[b * BLOCK_LEN..(b + 1) * BLOCK_LEN]).try_into().unwrap();
        let header = BlockHeader::parse(block).expect("encoded block");
        let byte = block::HEADER_LEN + at.index(usize::from(header.payload_len).max(1));
        block[byte] ^= mask;
        header.seal(block);
        let (events, stats) = decode(&file);
        prop_assert_eq!(stats.blocks, blocks.len() as u64);
        let decoded = records(&events);
        let before = sanitised(blocks[..b].iter().flatten().cloned());
        let after = sanitised(blocks[b + 1..].iter().flatten().cloned());
        prop_assert!(decoded.starts_with(&before), "blocks before {} changed", b);
        prop_assert!(decoded.ends_with(&after), "blocks after {} changed", b);
    }
}

#[test]
fn snapshot_then_fuller_block_share_a_place() {
    let mut enc = BlockEncoder::new();
    let frame = |t_us| {
        Record::Frame(Frame {
            t_us,
            ..Frame::default()
        })
    };
    assert!(enc.push(&frame(10_000)).unwrap().is_none());
    let partial = *enc.snapshot().expect("one frame");
    assert!(enc.push(&frame(20_000)).unwrap().is_none());
    let full = *enc.finish().expect("two frames");
    assert_eq!(partial[8..12], full[8..12], "same sequence number");
    let (events, _) = decode(&partial);
    assert_eq!(records(&events), vec![frame(10_000)]);
    let (events, _) = decode(&full);
    assert_eq!(records(&events), vec![frame(10_000), frame(20_000)]);
}

#[test]
fn frames_average_under_32_bytes_with_20hz_gps() {
    let mut enc = BlockEncoder::new();
    let mut bytes = 0;
    let frames = 100 * 600;
    for i in 0..frames {
        let t_us = 1_000_000 + i * 10_000;
        let f = Frame {
            t_us,
            accel: [1, -2, 2048],
            speed_mm_s: 4000,
            ..Frame::default()
        };
        bytes += enc.push(&Record::Frame(f)).unwrap().map_or(0, |b| b.len());
        if i % 5 == 0 {
            let g = GpsFix {
                t_us: t_us - 3_000,
                utc: Some(UtcTime {
                    days_since_2000: 7000,
                    ms_of_day: 1,
                }),
                lat_e7: Some(522_100_000),
                lon_e7: Some(68_800_000),
                speed_cm_s: Some(400),
                course_cdeg: Some(9000),
                alt_cm: Some(3000),
                fix: FixMode::Fix3d,
                sats: Some(9),
                hdop_d: Some(9),
            };
            bytes += enc.push(&Record::Gps(g)).unwrap().map_or(0, |b| b.len());
        }
    }
    let per_frame = bytes as f64 / frames as f64;
    assert!(per_frame <= 32.0, "{per_frame} bytes per frame");
}

proptest! {
    // Each case builds a whole ride: fewer cases keep the suite fast.
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn repeated_blocks_are_decoded_once(
        specs in ride(),
        copies in vec((any::<prop::sample::Index>(), any::<prop::sample::Index>()), 1..8),
    ) {
        let (file, blocks) = encode(&specs);
        let n = blocks.len();
        // Copies of blocks already in the file put after them: out of their
        // place and not after the last block before them.
        let mut order: Vec<usize> = (0..n).collect();
        for (at, which) in &copies {
            let at = at.index(order.len()) + 1;
            let which = order[which.index(at)];
            order.insert(at, which);
        }
        let dirty: Vec<u8> = order
            .iter()
            .flat_map(|&b| file[b * BLOCK_LEN..(b + 1) * BLOCK_LEN].iter().copied())
            .collect();
        let (events, stats) = decode(&dirty);
        let repeated = copies.len() as u64;
        prop_assert_eq!(stats.repeated_blocks, repeated, "{:?}", order);
        prop_assert_eq!(stats.blocks_lost, 0);
        prop_assert_eq!(stats.bytes_skipped, repeated * BLOCK_LEN as u64);
        prop_assert_eq!(records(&events), sanitised(blocks.concat()));
    }
}
