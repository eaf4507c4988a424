//! The MCAP container, written front to back: the header, schemas and
//! channels, messages in zstd-compressed chunks each followed by its message
//! indexes, metadata, and a summary (schemas, channels, statistics, chunk and
//! metadata indexes, their offsets) with every CRC the format defines.
//!
//! Written here rather than with the `mcap` crate's writer (the tests read
//! every file back with that crate): its writer hands each field of each
//! record to zstd's streaming encoder as its own small write, and those calls
//! cost more than the compression itself, so a 64 MiB log took 4-7 s of CPU.
//! Here a chunk's records are gathered in memory and compressed in one call.

use std::collections::BTreeMap;
use std::io::{self, Write};

/// The file's first and last eight bytes.
const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";

/// Record opcodes of the MCAP specification.
mod op {
    pub const HEADER: u8 = 0x01;
    pub const FOOTER: u8 = 0x02;
    pub const SCHEMA: u8 = 0x03;
    pub const CHANNEL: u8 = 0x04;
    pub const MESSAGE: u8 = 0x05;
    pub const CHUNK: u8 = 0x06;
    pub const MESSAGE_INDEX: u8 = 0x07;
    pub const CHUNK_INDEX: u8 = 0x08;
    pub const STATISTICS: u8 = 0x0B;
    pub const METADATA: u8 = 0x0C;
    pub const METADATA_INDEX: u8 = 0x0D;
    pub const SUMMARY_OFFSET: u8 = 0x0E;
    pub const DATA_END: u8 = 0x0F;
}

/// Uncompressed bytes a chunk gathers before it is compressed and written:
/// big enough that zstd finds the repetition between frames, small enough
/// for a viewer to seek in a ride.
pub const CHUNK_BYTES: usize = 4 << 20;

/// zstd's level: its fastest positive one. On the 7.3 h log, level 1 with
/// 4 MiB chunks made no larger file than the default level 3 with 1 MiB
/// chunks (169 against 174 MB, `docs/robustness.md`).
const ZSTD_LEVEL: i32 = 1;

/// Little-endian record fields, appended to a byte vector.
trait Fields {
    fn u8(&mut self, v: u8) -> &mut Self;
    fn u16(&mut self, v: u16) -> &mut Self;
    fn u32(&mut self, v: u32) -> &mut Self;
    fn u64(&mut self, v: u64) -> &mut Self;
    /// A string or byte array: its `u32` length, then its bytes.
    fn prefixed(&mut self, bytes: &[u8]) -> &mut Self;
}

impl Fields for Vec<u8> {
    fn u8(&mut self, v: u8) -> &mut Self {
        self.push(v);
        self
    }
    fn u16(&mut self, v: u16) -> &mut Self {
        self.extend_from_slice(&v.to_le_bytes());
        self
    }
    fn u32(&mut self, v: u32) -> &mut Self {
        self.extend_from_slice(&v.to_le_bytes());
        self
    }
    fn u64(&mut self, v: u64) -> &mut Self {
        self.extend_from_slice(&v.to_le_bytes());
        self
    }
    fn prefixed(&mut self, bytes: &[u8]) -> &mut Self {
        self.u32(len32(bytes.len()));
        self.extend_from_slice(bytes);
        self
    }
}

/// A length as the format's `u32`; nothing this writer builds comes near
/// 4 GiB (chunks are [`CHUNK_BYTES`]), so a longer one is a bug.
fn len32(len: usize) -> u32 {
    u32::try_from(len).expect("an MCAP field of 4 GiB")
}

/// `body` as a record: opcode, `u64` length, body.
fn record(op: u8, body: &[u8]) -> Vec<u8> {
    let mut r = Vec::with_capacity(9 + body.len());
    r.u8(op).u64(body.len() as u64);
    r.extend_from_slice(body);
    r
}

/// Message times of a chunk or a file: first and last log time.
#[derive(Clone, Copy)]
struct Bounds(Option<(u64, u64)>);

impl Bounds {
    fn take(&mut self, t: u64) {
        self.0 = Some(self.0.map_or((t, t), |(lo, hi)| (lo.min(t), hi.max(t))));
    }
    fn get(self) -> (u64, u64) {
        self.0.unwrap_or((0, 0))
    }
}

/// The chunk being gathered.
struct Chunk {
    records: Vec<u8>,
    bounds: Bounds,
    /// Per channel, each message's log time and offset in `records`.
    indexes: BTreeMap<u16, Vec<(u64, u64)>>,
}

/// A write to `out` that also counts the offset and keeps the data
/// section's CRC.
struct Counted<W> {
    out: W,
    position: u64,
    crc: crc32fast::Hasher,
}

impl<W: Write> Counted<W> {
    fn put(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.out.write_all(bytes)?;
        self.crc.update(bytes);
        self.position += bytes.len() as u64;
        Ok(())
    }
}

/// An MCAP file being written on `W`.
pub struct McapFile<W: Write> {
    out: Counted<W>,
    /// Schema and channel records, repeated in the summary.
    schemas: Vec<u8>,
    channels: Vec<u8>,
    schema_count: u16,
    channel_count: u16,
    chunk: Chunk,
    chunk_bytes: usize,
    compressor: zstd::bulk::Compressor<'static>,
    chunk_indexes: Vec<u8>,
    chunk_count: u32,
    metadata_indexes: Vec<u8>,
    metadata_count: u32,
    message_counts: BTreeMap<u16, u64>,
    bounds: Bounds,
}

impl<W: Write> McapFile<W> {
    /// Starts a file on `out`: the magic and the header naming `library`.
    ///
    /// # Errors
    /// When `out` fails.
    pub fn new(out: W, library: &str) -> io::Result<Self> {
        Self::with_chunk_bytes(out, library, CHUNK_BYTES)
    }

    /// As [`Self::new`], with chunks of about `chunk_bytes` uncompressed.
    ///
    /// # Errors
    /// When `out` fails.
    pub fn with_chunk_bytes(out: W, library: &str, chunk_bytes: usize) -> io::Result<Self> {
        let mut file = Self {
            out: Counted {
                out,
                position: 0,
                crc: crc32fast::Hasher::new(),
            },
            schemas: Vec::new(),
            channels: Vec::new(),
            schema_count: 0,
            channel_count: 0,
            chunk: Chunk {
                records: Vec::with_capacity(chunk_bytes + 4096),
                bounds: Bounds(None),
                indexes: BTreeMap::new(),
            },
            chunk_bytes,
            compressor: zstd::bulk::Compressor::new(ZSTD_LEVEL)?,
            chunk_indexes: Vec::new(),
            chunk_count: 0,
            metadata_indexes: Vec::new(),
            metadata_count: 0,
            message_counts: BTreeMap::new(),
            bounds: Bounds(None),
        };
        file.out.put(MAGIC)?;
        let mut header = Vec::new();
        header.prefixed(b"").prefixed(library.as_bytes());
        file.out.put(&record(op::HEADER, &header))?;
        Ok(file)
    }

    /// Adds a schema; returns its id (from 1).
    ///
    /// # Errors
    /// When `out` fails.
    pub fn add_schema(&mut self, name: &str, encoding: &str, data: &[u8]) -> io::Result<u16> {
        self.schema_count += 1;
        let mut body = Vec::new();
        body.u16(self.schema_count)
            .prefixed(name.as_bytes())
            .prefixed(encoding.as_bytes())
            .prefixed(data);
        let r = record(op::SCHEMA, &body);
        self.out.put(&r)?;
        self.schemas.extend_from_slice(&r);
        Ok(self.schema_count)
    }

    /// Adds a channel on `topic` of messages of schema `schema_id` in
    /// `message_encoding`; returns its id (from 0).
    ///
    /// # Errors
    /// When `out` fails.
    pub fn add_channel(
        &mut self,
        schema_id: u16,
        topic: &str,
        message_encoding: &str,
    ) -> io::Result<u16> {
        let id = self.channel_count;
        self.channel_count += 1;
        let mut body = Vec::new();
        body.u16(id)
            .u16(schema_id)
            .prefixed(topic.as_bytes())
            .prefixed(message_encoding.as_bytes())
            // No channel metadata: an empty map.
            .u32(0);
        let r = record(op::CHANNEL, &body);
        self.out.put(&r)?;
        self.channels.extend_from_slice(&r);
        self.message_counts.insert(id, 0);
        Ok(id)
    }

    /// Adds a message to the current chunk, which is written when full.
    ///
    /// # Errors
    /// When `out` fails.
    pub fn message(
        &mut self,
        channel_id: u16,
        sequence: u32,
        (log_time, publish_time): (u64, u64),
        data: &[u8],
    ) -> io::Result<()> {
        let chunk = &mut self.chunk;
        chunk
            .indexes
            .entry(channel_id)
            .or_default()
            .push((log_time, chunk.records.len() as u64));
        chunk
            .records
            .u8(op::MESSAGE)
            .u64(22 + data.len() as u64)
            .u16(channel_id)
            .u32(sequence)
            .u64(log_time)
            .u64(publish_time)
            .extend_from_slice(data);
        chunk.bounds.take(log_time);
        self.bounds.take(log_time);
        *self.message_counts.entry(channel_id).or_default() += 1;
        if self.chunk.records.len() >= self.chunk_bytes {
            self.write_chunk()?;
        }
        Ok(())
    }

    /// Writes the chunk gathered so far, compressed in one call, then its
    /// message indexes, and keeps its chunk index for the summary.
    fn write_chunk(&mut self) -> io::Result<()> {
        if self.chunk.records.is_empty() {
            return Ok(());
        }
        let records = &self.chunk.records;
        let compressed = self.compressor.compress(records)?;
        let (start, end) = self.chunk.bounds.get();
        let chunk_start = self.out.position;
        let mut head = Vec::with_capacity(64);
        head.u64(start)
            .u64(end)
            .u64(records.len() as u64)
            .u32(crc32fast::hash(records))
            .prefixed(b"zstd")
            .u64(compressed.len() as u64);
        let mut prefix = Vec::with_capacity(9 + head.len());
        prefix
            .u8(op::CHUNK)
            .u64((head.len() + compressed.len()) as u64)
            .extend_from_slice(&head);
        self.out.put(&prefix)?;
        self.out.put(&compressed)?;
        let chunk_length = self.out.position - chunk_start;

        let indexes_start = self.out.position;
        let mut offsets = Vec::new();
        for (&channel_id, entries) in &self.chunk.indexes {
            offsets.u16(channel_id).u64(self.out.position);
            let mut body = Vec::with_capacity(6 + 16 * entries.len());
            body.u16(channel_id).u32(len32(16 * entries.len()));
            for &(t, offset) in entries {
                body.u64(t).u64(offset);
            }
            self.out.put(&record(op::MESSAGE_INDEX, &body))?;
        }
        let mut index = Vec::new();
        index
            .u64(start)
            .u64(end)
            .u64(chunk_start)
            .u64(chunk_length)
            .prefixed(&offsets)
            .u64(self.out.position - indexes_start)
            .prefixed(b"zstd")
            .u64(compressed.len() as u64)
            .u64(self.chunk.records.len() as u64);
        self.chunk_indexes
            .extend_from_slice(&record(op::CHUNK_INDEX, &index));
        self.chunk_count += 1;
        self.chunk.records.clear();
        self.chunk.indexes.clear();
        self.chunk.bounds = Bounds(None);
        Ok(())
    }

    /// Writes a metadata record `name` of `pairs` (after the messages so
    /// far), indexed in the summary.
    ///
    /// # Errors
    /// When `out` fails.
    pub fn metadata(&mut self, name: &str, pairs: &BTreeMap<String, String>) -> io::Result<()> {
        self.write_chunk()?;
        let mut map = Vec::new();
        for (k, v) in pairs {
            map.prefixed(k.as_bytes()).prefixed(v.as_bytes());
        }
        let mut body = Vec::new();
        body.prefixed(name.as_bytes()).prefixed(&map);
        let r = record(op::METADATA, &body);
        let mut index = Vec::new();
        index
            .u64(self.out.position)
            .u64(r.len() as u64)
            .prefixed(name.as_bytes());
        self.metadata_indexes
            .extend_from_slice(&record(op::METADATA_INDEX, &index));
        self.metadata_count += 1;
        self.out.put(&r)
    }

    /// Writes the last chunk, the data section's end and the summary; the
    /// file is complete. Returns the output.
    ///
    /// # Errors
    /// When `out` fails.
    pub fn finish(mut self) -> io::Result<W> {
        self.write_chunk()?;
        let data_crc = self.out.crc.clone().finalize();
        self.out
            .put(&record(op::DATA_END, &data_crc.to_le_bytes()))?;

        // From here the CRC is the summary's.
        self.out.crc = crc32fast::Hasher::new();
        let summary_start = self.out.position;
        let (lo, hi) = self.bounds.get();
        let mut counts = Vec::new();
        for (&id, &n) in &self.message_counts {
            counts.u16(id).u64(n);
        }
        let mut stats = Vec::new();
        stats
            .u64(self.message_counts.values().sum())
            .u16(self.schema_count)
            .u32(u32::from(self.channel_count))
            // No attachments.
            .u32(0)
            .u32(self.metadata_count)
            .u32(self.chunk_count)
            .u64(lo)
            .u64(hi)
            .prefixed(&counts);
        let groups = [
            (op::SCHEMA, std::mem::take(&mut self.schemas)),
            (op::CHANNEL, std::mem::take(&mut self.channels)),
            (op::STATISTICS, record(op::STATISTICS, &stats)),
            (op::CHUNK_INDEX, std::mem::take(&mut self.chunk_indexes)),
            (
                op::METADATA_INDEX,
                std::mem::take(&mut self.metadata_indexes),
            ),
        ];
        let mut offsets = Vec::new();
        for (group, bytes) in groups.iter().filter(|g| !g.1.is_empty()) {
            let mut body = Vec::new();
            body.u8(*group)
                .u64(self.out.position)
                .u64(bytes.len() as u64);
            offsets.extend_from_slice(&record(op::SUMMARY_OFFSET, &body));
            self.out.put(bytes)?;
        }
        let summary_offset_start = self.out.position;
        self.out.put(&offsets)?;
        let mut footer = Vec::new();
        footer
            .u8(op::FOOTER)
            .u64(20)
            .u64(summary_start)
            .u64(summary_offset_start);
        self.out.put(&footer)?;
        // The summary CRC covers the footer up to the CRC itself.
        let summary_crc = self.out.crc.clone().finalize();
        self.out.put(&summary_crc.to_le_bytes())?;
        self.out.put(MAGIC)?;
        Ok(self.out.out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file of `n` messages on two channels in chunks of `chunk_bytes`.
    fn file(n: u64, chunk_bytes: usize) -> Vec<u8> {
        let mut f = McapFile::with_chunk_bytes(Vec::new(), "test 1", chunk_bytes).unwrap();
        let s = f.add_schema("a/msg/A", "ros2msg", b"float64 x\n").unwrap();
        let a = f.add_channel(s, "/a", "cdr").unwrap();
        let t = f.add_schema("b", "jsonschema", b"{}").unwrap();
        let b = f.add_channel(t, "/b", "json").unwrap();
        for i in 0..n {
            let data = (i as f64).to_le_bytes();
            f.message(a, i as u32, (1_000 + i, i), &data).unwrap();
            if i % 10 == 0 {
                f.message(
                    b,
                    i as u32,
                    (1_000 + i, i),
                    format!("{{\"i\":{i}}}").as_bytes(),
                )
                .unwrap();
            }
        }
        let meta = BTreeMap::from([("run".to_string(), "3".to_string())]);
        f.metadata("wobblog", &meta).unwrap();
        f.finish().unwrap()
    }

    /// Every record of `bytes` in order, chunks opened, with the `mcap`
    /// crate's reader checking each CRC.
    fn records(bytes: &[u8]) -> Vec<mcap::records::Record<'static>> {
        mcap::read::LinearReader::new(bytes)
            .unwrap()
            .map(|r| r.unwrap().into_owned())
            .collect()
    }

    #[test]
    fn the_mcap_crate_reads_every_message_back_across_chunks() {
        // About 45 bytes a message: some 24 chunks of 1 KiB.
        let bytes = file(500, 1024);
        let check_crcs = mcap::read::Options::ValidateChunkCrcs.into();
        let messages: Vec<_> = mcap::MessageStream::new_with_options(&bytes, check_crcs)
            .unwrap()
            .map(Result::unwrap)
            .collect();
        assert_eq!(messages.len(), 550);
        let a: Vec<_> = messages
            .iter()
            .filter(|m| m.channel.topic == "/a")
            .collect();
        for (i, m) in a.iter().enumerate() {
            assert_eq!(m.log_time, 1_000 + i as u64);
            assert_eq!(m.publish_time, i as u64);
            assert_eq!(m.sequence, i as u32);
            assert_eq!(m.data.as_ref(), (i as f64).to_le_bytes());
            let schema = m.channel.schema.as_ref().unwrap();
            assert_eq!(
                (schema.name.as_str(), schema.encoding.as_str()),
                ("a/msg/A", "ros2msg")
            );
        }
        let b: Vec<_> = messages
            .iter()
            .filter(|m| m.channel.topic == "/b")
            .collect();
        assert_eq!(b[3].data.as_ref(), b"{\"i\":30}");
        assert_eq!(b[3].channel.message_encoding, "json");

        let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
        let stats = summary.stats.as_ref().unwrap();
        assert_eq!(stats.message_count, 550);
        assert_eq!(stats.channel_message_counts[&0], 500);
        assert_eq!(stats.channel_message_counts[&1], 50);
        assert_eq!(
            (stats.message_start_time, stats.message_end_time),
            (1_000, 1_499)
        );
        assert_eq!(stats.chunk_count as usize, summary.chunk_indexes.len());
        assert!(summary.chunk_indexes.len() > 20);
        assert_eq!((summary.schemas.len(), summary.channels.len()), (2, 2));
        // The indexes lead to every message: chunk by chunk, through the
        // message indexes, as a seeking viewer reads.
        let mut indexed = 0;
        for chunk in &summary.chunk_indexes {
            assert_eq!(chunk.compression, "zstd");
            let offsets = summary.read_message_indexes(&bytes, chunk).unwrap();
            for entries in offsets.values() {
                for entry in entries {
                    let m = summary.seek_message(&bytes, chunk, entry).unwrap();
                    assert_eq!(m.log_time, entry.log_time);
                    indexed += 1;
                }
            }
        }
        assert_eq!(indexed, 550);
        let meta = mcap::read::metadata(&bytes, &summary.metadata_indexes[0]).unwrap();
        assert_eq!(meta.name, "wobblog");
        assert_eq!(meta.metadata["run"], "3");
    }

    #[test]
    fn every_crc_is_right_and_a_flipped_byte_is_caught() {
        let bytes = file(200, 512);
        let all = records(&bytes);
        let data_end = all
            .iter()
            .find_map(|r| match r {
                mcap::records::Record::DataEnd(d) => Some(d.data_section_crc),
                _ => None,
            })
            .unwrap();
        let footer = mcap::read::footer(&bytes).unwrap();
        // The data end record (13 bytes) stands just before the summary.
        let data_end_at = footer.summary_start as usize - 13;
        assert_eq!(bytes[data_end_at], op::DATA_END);
        assert_eq!(data_end, crc32fast::hash(&bytes[..data_end_at]));
        assert!(matches!(all.last(), Some(mcap::records::Record::Footer(_))));
        let crc_at = bytes.len() - 8 - 4;
        assert_eq!(
            footer.summary_crc,
            crc32fast::hash(&bytes[footer.summary_start as usize..crc_at])
        );
        // A byte of a compressed chunk changed: the reader refuses it.
        let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
        let chunk = &summary.chunk_indexes[1];
        let mut bad = bytes.clone();
        let at = (chunk.chunk_start_offset + chunk.chunk_length - 3) as usize;
        bad[at] ^= 0x40;
        assert!(mcap::MessageStream::new(&bad).unwrap().any(|m| m.is_err()));
    }

    /// Messages out of time order in one chunk: its index says the latest
    /// time, not the last message's; the length of its message indexes is
    /// theirs alone (record headers of 9 bytes, a body of 6 bytes and 16
    /// per message), not counted from the chunk's start.
    #[test]
    fn a_chunk_index_has_the_latest_time_and_its_message_indexes_length() {
        let mut f = McapFile::with_chunk_bytes(Vec::new(), "test 1", 1 << 20).unwrap();
        let s = f.add_schema("b", "jsonschema", b"{}").unwrap();
        let a = f.add_channel(s, "/a", "json").unwrap();
        let b = f.add_channel(s, "/b", "json").unwrap();
        for (channel, t) in [(a, 1_000), (b, 1_009), (a, 1_005), (a, 1_002)] {
            f.message(channel, 0, (t, t), b"{}").unwrap();
        }
        let bytes = f.finish().unwrap();
        let all = records(&bytes);
        let index_len: u64 = all
            .iter()
            .filter_map(|r| match r {
                mcap::records::Record::MessageIndex(m) => Some(9 + 6 + 16 * m.records.len() as u64),
                _ => None,
            })
            .sum();
        assert_eq!(index_len, 2 * 15 + 4 * 16);
        let chunk_indexes: Vec<_> = all
            .iter()
            .filter_map(|r| match r {
                mcap::records::Record::ChunkIndex(c) => Some(c),
                _ => None,
            })
            .collect();
        assert_eq!(chunk_indexes.len(), 1);
        let c = chunk_indexes[0];
        assert_eq!((c.message_start_time, c.message_end_time), (1_000, 1_009));
        assert_eq!(c.message_index_length, index_len);
    }

    #[test]
    fn a_file_without_messages_is_still_whole() {
        let mut f = McapFile::new(Vec::new(), "test 1").unwrap();
        let s = f.add_schema("b", "jsonschema", b"{}").unwrap();
        f.add_channel(s, "/events", "json").unwrap();
        let bytes = f.finish().unwrap();
        assert_eq!(mcap::MessageStream::new(&bytes).unwrap().count(), 0);
        let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
        assert!(summary.chunk_indexes.is_empty());
        assert_eq!(summary.channels[&0].topic, "/events");
        assert_eq!(&bytes[bytes.len() - 8..], MAGIC);
    }
}
