//! Byte layout of each record inside a block's payload.
//!
//! Every record starts with a tag byte. Frames carry their time as the
//! difference between their delta from the block's frame cursor (the
//! previous frame, or the block's t0) and the nominal frame period, zigzag
//! coded, so a frame on time costs one byte; they advance the cursor. Every other record carries a signed (zigzag) delta from the
//! cursor and leaves it alone, so a GPS fix stamped when its sentence began
//! may precede the frame written just before it. Tags below 0x80 have a fixed
//! layout per major version; tags from 0x80 up are followed by a length byte
//! so that readers skip the ones they do not know.

use super::record::*;
use super::varint;

/// Tag: 100 Hz frame.
pub const TAG_FRAME: u8 = 0x01;
/// Bytes of a frame after its time delta: six IMU words, steering, wheel
/// count, edge age and speed (two bytes each), the status byte.
const FRAME_FIXED_LEN: usize = 2 * 10 + 1;
/// Tag: GPS fix.
pub const TAG_GPS: u8 = 0x02;
/// Tag: UTC sync pair.
pub const TAG_UTC_SYNC: u8 = 0x03;
/// Tag: wobble alert on/off.
pub const TAG_ALERT: u8 = 0x04;
/// Tag: rider marker.
pub const TAG_MARKER: u8 = 0x05;
/// Tag: dropout.
pub const TAG_DROPOUT: u8 = 0x06;
/// Tag: fault.
pub const TAG_FAULT: u8 = 0x07;
/// Tag: log info (length-prefixed).
pub const TAG_LOG_INFO: u8 = 0x80;
/// Tag: channel definition (length-prefixed).
pub const TAG_CHANNEL: u8 = 0x81;
/// Tag: configuration line (length-prefixed).
pub const TAG_CONFIG: u8 = 0x82;
/// Tag: a kick's measured ring-down (length-prefixed, format 1.1).
pub const TAG_KICK: u8 = 0x83;
/// Tag: the margin warning's estimate or switching (length-prefixed,
/// format 1.2).
pub const TAG_MARGIN: u8 = 0x84;
/// A speed field on the card when the speed is unknown.
const SPEED_UNKNOWN: u16 = u16::MAX;
/// Nominal frame period: frame time deltas are stored relative to it.
pub const FRAME_PERIOD_US: i64 = 10_000;
/// First tag of the length-prefixed range.
pub const FIRST_SIZED_TAG: u8 = 0x80;
/// Longest body of a length-prefixed record.
pub const MAX_SIZED_BODY: usize = 255;
/// Longest encoded record of any kind.
pub const MAX_RECORD_LEN: usize = 2 + MAX_SIZED_BODY;

// GPS presence bits; bits 6-7 hold the fix mode.
const GPS_UTC: u8 = 1 << 0;
const GPS_POS: u8 = 1 << 1;
const GPS_SPEED: u8 = 1 << 2;
const GPS_COURSE: u8 = 1 << 3;
const GPS_ALT: u8 = 1 << 4;
const GPS_QUALITY: u8 = 1 << 5;
const GPS_FIX_SHIFT: u32 = 6;
/// Stored for an unknown satellite count or HDOP inside a quality pair.
const UNKNOWN_U8: u8 = 0xff;

/// Why a record cannot be encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum EncodeError {
    /// A header record's text is longer than a record can hold.
    TooLong,
    /// The record is more than 2^63 µs away from the block's time base.
    TimeOutOfRange,
}

impl core::fmt::Display for EncodeError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::TooLong => f.write_str("record text too long"),
            Self::TimeOutOfRange => f.write_str("record time too far from block time base"),
        }
    }
}

/// Why the records of a valid block cannot all be read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum RecordError {
    /// A record runs past the end of the payload.
    Truncated,
    /// A fixed-layout tag this reader does not know: the rest of the block
    /// cannot be delimited.
    UnknownTag(u8),
    /// A field holds an impossible value (bad UTF-8, fix mode 3, time overflow).
    Invalid(u8),
}

impl core::fmt::Display for RecordError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Truncated => f.write_str("record truncated"),
            Self::UnknownTag(t) => write!(f, "unknown record tag 0x{t:02x}"),
            Self::Invalid(t) => write!(f, "invalid field in record tag 0x{t:02x}"),
        }
    }
}

/// Appends bytes to a fixed buffer; every write reports overflow as `None`.
struct Writer<'a> {
    out: &'a mut [u8],
    len: usize,
}

impl Writer<'_> {
    fn bytes(&mut self, bytes: &[u8]) -> Option<()> {
        let end = self.len.checked_add(bytes.len())?;
        self.out.get_mut(self.len..end)?.copy_from_slice(bytes);
        self.len = end;
        Some(())
    }
    fn u8(&mut self, v: u8) -> Option<()> {
        self.bytes(&[v])
    }
    fn uvar(&mut self, v: u64) -> Option<()> {
        let n = varint::write_u64(v, self.out.get_mut(self.len..)?)?;
        self.len += n;
        Some(())
    }
}

/// Encodes `rec` at the start of `out` relative to the frame `cursor_us`.
///
/// Returns the bytes used, `Ok(None)` if `out` is too short, or an error if
/// the record can never be encoded. A frame must not precede the cursor (the
/// encoder starts a new block for that).
pub fn encode(
    rec: &Record<'_>,
    cursor_us: u64,
    out: &mut [u8],
) -> Result<Option<usize>, EncodeError> {
    let t = rec.t_us();
    let sdelta = i64::try_from(i128::from(t) - i128::from(cursor_us))
        .map_err(|_| EncodeError::TimeOutOfRange)?;
    let mut w = Writer { out, len: 0 };
    let fits = match rec {
        Record::Frame(f) => {
            let delta = i64::try_from(t.saturating_sub(cursor_us))
                .map_err(|_| EncodeError::TimeOutOfRange)?;
            encode_frame(&mut w, f, delta)
        }
        Record::Gps(g) => encode_gps(&mut w, g, sdelta),
        Record::UtcSync(u) => fixed(&mut w, TAG_UTC_SYNC, sdelta, &u.unix_ms.to_le_bytes()),
        Record::Alert(a) => {
            let mut body = [0u8; 5];
            body[0] = u8::from(a.on);
            body[1..3].copy_from_slice(&a.freq_chz.to_le_bytes());
            body[3..5].copy_from_slice(&a.amp_cdeg.to_le_bytes());
            fixed(&mut w, TAG_ALERT, sdelta, &body)
        }
        Record::Marker(m) => fixed(&mut w, TAG_MARKER, sdelta, &m.id.to_le_bytes()),
        Record::Dropout(d) => {
            let mut body = [0u8; 5];
            body[..4].copy_from_slice(&d.frames_lost.to_le_bytes());
            body[4] = d.reason.code();
            fixed(&mut w, TAG_DROPOUT, sdelta, &body)
        }
        Record::Fault(x) => {
            let c = x.count.to_le_bytes();
            fixed(
                &mut w,
                TAG_FAULT,
                sdelta,
                &[x.source.code(), x.code, c[0], c[1]],
            )
        }
        Record::LogInfo(i) => {
            let mut head = [0u8; 18];
            head[..2].copy_from_slice(&i.sample_rate_hz.to_le_bytes());
            head[2..6].copy_from_slice(&i.run.to_le_bytes());
            head[6..].copy_from_slice(&i.device_id);
            sized(
                &mut w,
                TAG_LOG_INFO,
                sdelta,
                &[&head, i.firmware.as_bytes()],
            )?
        }
        Record::Channel(c) => {
            let name = c.name.as_bytes();
            let name_len = u8::try_from(name.len()).map_err(|_| EncodeError::TooLong)?;
            let s = c.counts_per_unit.to_le_bytes();
            let head = [c.index, s[0], s[1], s[2], s[3], name_len];
            sized(
                &mut w,
                TAG_CHANNEL,
                sdelta,
                &[&head, name, c.unit.as_bytes()],
            )?
        }
        Record::Config(c) => sized(&mut w, TAG_CONFIG, sdelta, &[c.text.as_bytes()])?,
        Record::Kick(k) => {
            let mut body = [0u8; 11];
            body[0..2].copy_from_slice(&k.speed_mm_s.unwrap_or(SPEED_UNKNOWN).to_le_bytes());
            body[2..4].copy_from_slice(&k.freq_chz.to_le_bytes());
            body[4..6].copy_from_slice(&k.sigma_milli_per_s.to_le_bytes());
            body[6..8].copy_from_slice(&k.sigma_se_milli_per_s.to_le_bytes());
            body[8..10].copy_from_slice(&k.amp_cdeg.to_le_bytes());
            body[10] = k.segments;
            sized(&mut w, TAG_KICK, sdelta, &[&body])?
        }
        Record::Margin(m) => {
            let mut body = [0u8; 10];
            body[0] = m.state.code();
            for (i, v) in [m.speed_mm_s, m.lower_mm_s, m.estimate_mm_s, m.upper_mm_s]
                .into_iter()
                .enumerate()
            {
                body[1 + 2 * i..3 + 2 * i]
                    .copy_from_slice(&v.unwrap_or(SPEED_UNKNOWN).to_le_bytes());
            }
            body[9] = m.kicks;
            sized(&mut w, TAG_MARGIN, sdelta, &[&body])?
        }
    };
    Ok(fits.map(|()| w.len))
}

fn encode_frame(w: &mut Writer<'_>, f: &Frame, delta_us: i64) -> Option<()> {
    w.u8(TAG_FRAME)?;
    w.uvar(varint::zigzag(delta_us - FRAME_PERIOD_US))?;
    for v in f.accel.iter().chain(&f.gyro) {
        w.bytes(&v.to_le_bytes())?;
    }
    w.bytes(&f.steer_cdeg.to_le_bytes())?;
    w.bytes(&f.wheel_count.to_le_bytes())?;
    w.bytes(&f.wheel_edge_age_us.to_le_bytes())?;
    w.bytes(&f.speed_mm_s.to_le_bytes())?;
    w.u8(f.status.0)
}

fn encode_gps(w: &mut Writer<'_>, g: &GpsFix, sdelta: i64) -> Option<()> {
    let fix_bits = match g.fix {
        FixMode::None => 0,
        FixMode::Fix2d => 1,
        FixMode::Fix3d => 2,
    };
    let position = g.lat_e7.zip(g.lon_e7);
    let quality = g.sats.is_some() || g.hdop_d.is_some();
    let bit = |present: bool, mask: u8| if present { mask } else { 0 };
    let flags = bit(g.utc.is_some(), GPS_UTC)
        | bit(position.is_some(), GPS_POS)
        | bit(g.speed_cm_s.is_some(), GPS_SPEED)
        | bit(g.course_cdeg.is_some(), GPS_COURSE)
        | bit(g.alt_cm.is_some(), GPS_ALT)
        | bit(quality, GPS_QUALITY)
        | (fix_bits << GPS_FIX_SHIFT);
    w.u8(TAG_GPS)?;
    w.uvar(varint::zigzag(sdelta))?;
    w.u8(flags)?;
    if let Some(utc) = g.utc {
        w.bytes(&utc.days_since_2000.to_le_bytes())?;
        w.bytes(&utc.ms_of_day.to_le_bytes())?;
    }
    if let Some((lat, lon)) = position {
        w.bytes(&lat.to_le_bytes())?;
        w.bytes(&lon.to_le_bytes())?;
    }
    if let Some(v) = g.speed_cm_s {
        w.bytes(&v.to_le_bytes())?;
    }
    if let Some(v) = g.course_cdeg {
        w.bytes(&v.to_le_bytes())?;
    }
    if let Some(v) = g.alt_cm {
        w.bytes(&v.to_le_bytes())?;
    }
    if quality {
        w.u8(g.sats.map_or(UNKNOWN_U8, |s| s.min(UNKNOWN_U8 - 1)))?;
        w.u8(g.hdop_d.map_or(UNKNOWN_U8, |h| h.min(UNKNOWN_U8 - 1)))?;
    }
    Some(())
}

fn fixed(w: &mut Writer<'_>, tag: u8, sdelta: i64, body: &[u8]) -> Option<()> {
    w.u8(tag)?;
    w.uvar(varint::zigzag(sdelta))?;
    w.bytes(body)
}

/// A length-prefixed record: tag, body length, then the body (signed time
/// delta followed by `parts`).
fn sized(
    w: &mut Writer<'_>,
    tag: u8,
    sdelta: i64,
    parts: &[&[u8]],
) -> Result<Option<()>, EncodeError> {
    let mut delta = [0u8; varint::MAX_LEN];
    let delta_len = varint::write_u64(varint::zigzag(sdelta), &mut delta).unwrap_or(0);
    let body_len = delta_len + parts.iter().map(|p| p.len()).sum::<usize>();
    let body_len = u8::try_from(body_len).map_err(|_| EncodeError::TooLong)?;
    let mut write = || -> Option<()> {
        w.u8(tag)?;
        w.u8(body_len)?;
        w.bytes(&delta[..delta_len])?;
        parts.iter().try_for_each(|p| w.bytes(p))
    };
    Ok(write())
}

/// Reads fields from a record body; every read reports truncation.
struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], RecordError> {
        let slice = self
            .bytes
            .get(self.pos..self.pos + N)
            .ok_or(RecordError::Truncated)?;
        self.pos += N;
        let mut out = [0u8; N];
        out.copy_from_slice(slice);
        Ok(out)
    }
    fn u8(&mut self) -> Result<u8, RecordError> {
        Ok(self.take::<1>()?[0])
    }
    fn u16(&mut self) -> Result<u16, RecordError> {
        self.take().map(u16::from_le_bytes)
    }
    fn i16(&mut self) -> Result<i16, RecordError> {
        self.take().map(i16::from_le_bytes)
    }
    fn u32(&mut self) -> Result<u32, RecordError> {
        self.take().map(u32::from_le_bytes)
    }
    fn i32(&mut self) -> Result<i32, RecordError> {
        self.take().map(i32::from_le_bytes)
    }
    fn uvar(&mut self) -> Result<u64, RecordError> {
        let (v, n) = varint::read_u64(&self.bytes[self.pos..]).ok_or(RecordError::Truncated)?;
        self.pos += n;
        Ok(v)
    }
    fn rest(&mut self) -> &'a [u8] {
        let rest = &self.bytes[self.pos..];
        self.pos = self.bytes.len();
        rest
    }
    fn str(bytes: &'a [u8], tag: u8) -> Result<&'a str, RecordError> {
        core::str::from_utf8(bytes).map_err(|_| RecordError::Invalid(tag))
    }
}

/// Iterates over the records of one block's payload.
///
/// After the first error the iterator ends: a fixed-layout record that cannot
/// be read leaves nothing to delimit the next one.
#[derive(Clone, Debug)]
pub struct Records<'a> {
    payload: &'a [u8],
    pos: usize,
    cursor_us: u64,
    skipped_unknown: u32,
    failed: bool,
}

impl<'a> Records<'a> {
    /// Records of `payload`, a block whose time base is `t0_us`.
    #[must_use]
    pub fn new(payload: &'a [u8], t0_us: u64) -> Self {
        Self {
            payload,
            pos: 0,
            cursor_us: t0_us,
            skipped_unknown: 0,
            failed: false,
        }
    }

    /// Payload bytes read so far: where the next record (or an unknown one
    /// skipped before it) starts.
    #[must_use]
    pub fn offset(&self) -> usize {
        self.pos
    }

    /// The next record if it is a frame that reads whole; otherwise
    /// nothing is read, and [`Iterator::next`] gives the record or its
    /// error. Nearly every record is a frame: inlined into a caller's loop,
    /// it is read without the dispatch on the tag and without a record
    /// built and taken apart again.
    #[inline(always)]
    pub fn next_frame(&mut self) -> Option<Frame> {
        if self.failed || self.payload.get(self.pos) != Some(&TAG_FRAME) {
            return None;
        }
        let mut r = Reader {
            bytes: self.payload,
            pos: self.pos + 1,
        };
        let frame = self.frame(&mut r).ok()?;
        self.pos = r.pos;
        Some(frame)
    }

    /// Length-prefixed records of unknown kinds skipped so far.
    #[must_use]
    pub fn skipped_unknown(&self) -> u32 {
        self.skipped_unknown
    }

    fn signed_time(&self, r: &mut Reader<'_>, tag: u8) -> Result<u64, RecordError> {
        let delta = varint::unzigzag(r.uvar()?);
        let t = i128::from(self.cursor_us) + i128::from(delta);
        u64::try_from(t).map_err(|_| RecordError::Invalid(tag))
    }

    fn next_record(&mut self) -> Result<Option<Record<'a>>, RecordError> {
        loop {
            let Some(&tag) = self.payload.get(self.pos) else {
                return Ok(None);
            };
            if tag >= FIRST_SIZED_TAG {
                let len = usize::from(
                    *self
                        .payload
                        .get(self.pos + 1)
                        .ok_or(RecordError::Truncated)?,
                );
                let start = self.pos + 2;
                let body = self
                    .payload
                    .get(start..start + len)
                    .ok_or(RecordError::Truncated)?;
                self.pos = start + len;
                let mut r = Reader {
                    bytes: body,
                    pos: 0,
                };
                match self.sized_record(tag, &mut r)? {
                    Some(rec) => return Ok(Some(rec)),
                    None => self.skipped_unknown += 1,
                }
            } else {
                let mut r = Reader {
                    bytes: self.payload,
                    pos: self.pos + 1,
                };
                let rec = self.fixed_record(tag, &mut r)?;
                self.pos = r.pos;
                return Ok(Some(rec));
            }
        }
    }

    /// A frame record's body, read by `r` (just past its tag).
    #[inline(always)]
    fn frame(&mut self, r: &mut Reader<'_>) -> Result<Frame, RecordError> {
        let t_us = varint::unzigzag(r.uvar()?)
            .checked_add(FRAME_PERIOD_US)
            .and_then(|d| u64::try_from(d).ok())
            .and_then(|d| self.cursor_us.checked_add(d))
            .ok_or(RecordError::Invalid(TAG_FRAME))?;
        // The fixed part taken at once: one length check for the
        // frame, not one per field (the host decodes millions).
        let b: [u8; FRAME_FIXED_LEN] = r.take()?;
        let word = |i: usize| [b[2 * i], b[2 * i + 1]];
        let int = |i: usize| i16::from_le_bytes(word(i));
        let frame = Frame {
            t_us,
            accel: [int(0), int(1), int(2)],
            gyro: [int(3), int(4), int(5)],
            steer_cdeg: int(6),
            wheel_count: u16::from_le_bytes(word(7)),
            wheel_edge_age_us: u16::from_le_bytes(word(8)),
            speed_mm_s: u16::from_le_bytes(word(9)),
            status: FrameStatus(b[20]),
        };
        self.cursor_us = t_us;
        Ok(frame)
    }

    fn fixed_record(&mut self, tag: u8, r: &mut Reader<'a>) -> Result<Record<'a>, RecordError> {
        Ok(match tag {
            TAG_FRAME => Record::Frame(self.frame(r)?),
            TAG_GPS => Record::Gps(self.gps(r)?),
            TAG_UTC_SYNC => {
                let t_us = self.signed_time(r, tag)?;
                let unix_ms = u64::from_le_bytes(r.take()?);
                Record::UtcSync(UtcSync { t_us, unix_ms })
            }
            TAG_ALERT => {
                let t_us = self.signed_time(r, tag)?;
                let on = match r.u8()? {
                    0 => false,
                    1 => true,
                    _ => return Err(RecordError::Invalid(tag)),
                };
                Record::Alert(Alert {
                    t_us,
                    on,
                    freq_chz: r.u16()?,
                    amp_cdeg: r.u16()?,
                })
            }
            TAG_MARKER => {
                let t_us = self.signed_time(r, tag)?;
                Record::Marker(Marker { t_us, id: r.u16()? })
            }
            TAG_DROPOUT => {
                let t_us = self.signed_time(r, tag)?;
                let frames_lost = r.u32()?;
                let reason = DropoutReason::from_code(r.u8()?);
                Record::Dropout(Dropout {
                    t_us,
                    frames_lost,
                    reason,
                })
            }
            TAG_FAULT => {
                let t_us = self.signed_time(r, tag)?;
                let source = FaultSource::from_code(r.u8()?);
                Record::Fault(Fault {
                    t_us,
                    source,
                    code: r.u8()?,
                    count: r.u16()?,
                })
            }
            other => return Err(RecordError::UnknownTag(other)),
        })
    }

    fn gps(&self, r: &mut Reader<'a>) -> Result<GpsFix, RecordError> {
        let t_us = self.signed_time(r, TAG_GPS)?;
        let flags = r.u8()?;
        let fix = match flags >> GPS_FIX_SHIFT {
            0 => FixMode::None,
            1 => FixMode::Fix2d,
            2 => FixMode::Fix3d,
            _ => return Err(RecordError::Invalid(TAG_GPS)),
        };
        let has = |bit: u8| flags & bit != 0;
        let mut g = GpsFix {
            t_us,
            fix,
            ..GpsFix::default()
        };
        if has(GPS_UTC) {
            g.utc = Some(UtcTime {
                days_since_2000: r.u16()?,
                ms_of_day: r.u32()?,
            });
        }
        if has(GPS_POS) {
            g.lat_e7 = Some(r.i32()?);
            g.lon_e7 = Some(r.i32()?);
        }
        if has(GPS_SPEED) {
            g.speed_cm_s = Some(r.u16()?);
        }
        if has(GPS_COURSE) {
            g.course_cdeg = Some(r.u16()?);
        }
        if has(GPS_ALT) {
            g.alt_cm = Some(r.i32()?);
        }
        if has(GPS_QUALITY) {
            let known = |v: u8| (v != UNKNOWN_U8).then_some(v);
            g.sats = known(r.u8()?);
            g.hdop_d = known(r.u8()?);
        }
        Ok(g)
    }

    /// `Ok(None)` for a length-prefixed tag this reader does not know.
    fn sized_record(&self, tag: u8, r: &mut Reader<'a>) -> Result<Option<Record<'a>>, RecordError> {
        let known = matches!(
            tag,
            TAG_LOG_INFO | TAG_CHANNEL | TAG_CONFIG | TAG_KICK | TAG_MARGIN
        );
        if !known {
            return Ok(None);
        }
        let t_us = self.signed_time(r, tag)?;
        Ok(Some(match tag {
            TAG_LOG_INFO => {
                let sample_rate_hz = r.u16()?;
                let run = r.u32()?;
                let device_id = r.take::<12>()?;
                let firmware = Reader::str(r.rest(), tag)?;
                Record::LogInfo(LogInfo {
                    t_us,
                    firmware,
                    device_id,
                    sample_rate_hz,
                    run,
                })
            }
            TAG_CHANNEL => {
                let index = r.u8()?;
                let counts_per_unit = f32::from_le_bytes(r.take()?);
                let name_len = usize::from(r.u8()?);
                let rest = r.rest();
                let name = rest.get(..name_len).ok_or(RecordError::Truncated)?;
                let name = Reader::str(name, tag)?;
                let unit = Reader::str(&rest[name_len..], tag)?;
                Record::Channel(ChannelDef {
                    t_us,
                    index,
                    name,
                    unit,
                    counts_per_unit,
                })
            }
            // Later minor versions may append fields: the rest is skipped.
            TAG_KICK => Record::Kick(KickRingDown {
                t_us,
                speed_mm_s: Some(r.u16()?).filter(|&v| v != SPEED_UNKNOWN),
                freq_chz: r.u16()?,
                sigma_milli_per_s: r.i16()?,
                sigma_se_milli_per_s: r.u16()?,
                amp_cdeg: r.u16()?,
                segments: r.u8()?,
            }),
            TAG_MARGIN => {
                let state = MarginState::from_code(r.u8()?);
                let mut speed = || Ok(Some(r.u16()?).filter(|&v| v != SPEED_UNKNOWN));
                Record::Margin(MarginRecord {
                    t_us,
                    state,
                    speed_mm_s: speed()?,
                    lower_mm_s: speed()?,
                    estimate_mm_s: speed()?,
                    upper_mm_s: speed()?,
                    kicks: r.u8()?,
                })
            }
            _ => Record::Config(ConfigLine {
                t_us,
                text: Reader::str(r.rest(), tag)?,
            }),
        }))
    }
}

impl<'a> Iterator for Records<'a> {
    type Item = Result<Record<'a>, RecordError>;

    #[inline]
    fn next(&mut self) -> Option<Self::Item> {
        if let Some(frame) = self.next_frame() {
            return Some(Ok(Record::Frame(frame)));
        }
        if self.failed {
            return None;
        }
        match self.next_record() {
            Ok(rec) => rec.map(Ok),
            Err(e) => {
                self.failed = true;
                Some(Err(e))
            }
        }
    }
}
