//! One checksummed NMEA line -> the fields it contributes to a fix.
//!
//! This is the only place that touches the `nmea` crate's types. It decides
//! which sentences are worth parsing at all (RMC, GGA, GLL, VTG, GSA, ZDA from
//! any talker), hands those to the crate, and converts what comes back into
//! the integer units of [`GpsFix`](crate::format::GpsFix). Everything else
//! (GSV, TXT, proprietary `$P...` sentences) is skipped without parsing.

use nmea::sentences::{FixType, GgaData, GllData, GsaData, RmcData, VtgData, ZdaData};
use nmea::ParseResult;

use crate::format::limits::{self, SATS_MAX, SPEED_CM_S_MAX};
use crate::format::{quantise_i32, FixMode, UtcTime};

/// Metres per second in one knot.
const MPS_PER_KNOT: f64 = 1852.0 / 3600.0;

/// The sentence types the GPS path merges.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Kind {
    /// Recommended minimum data: time, date, status, position, speed, course.
    Rmc,
    /// Fix data: time, quality, position, satellites, HDOP, altitude.
    Gga,
    /// Geographic position: time, status, position.
    Gll,
    /// Course and speed over ground.
    Vtg,
    /// DOP and active satellites: 2D/3D mode.
    Gsa,
    /// Time and date.
    Zda,
}

impl Kind {
    /// Number of kinds, for per-kind tables.
    pub const COUNT: usize = 6;

    /// Index into per-kind tables.
    #[must_use]
    pub const fn index(self) -> usize {
        self as usize
    }

    fn from_type(sentence_type: &str) -> Option<Self> {
        Some(match sentence_type {
            "RMC" => Self::Rmc,
            "GGA" => Self::Gga,
            "GLL" => Self::Gll,
            "VTG" => Self::Vtg,
            "GSA" => Self::Gsa,
            "ZDA" => Self::Zda,
            _ => return None,
        })
    }
}

/// What a sentence says about the validity of the fix.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Validity {
    /// The sentence carries no validity indication (VTG, ZDA).
    #[default]
    Unknown,
    /// RMC/GLL status `A`, or a GGA quality that is a real fix.
    Valid,
    /// RMC/GLL status `V`, or GGA quality 0 (none), 6 (dead reckoning),
    /// 7 (manual) or 8 (simulator).
    Invalid,
}

/// The fields one sentence contributes, already in the record's units.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Update {
    /// UTC time of day of the fix, ms since midnight.
    pub tod_ms: Option<u32>,
    /// UTC date, days since 2000-01-01.
    pub date_days: Option<u16>,
    /// Latitude, 1e-7 degrees.
    pub lat_e7: Option<i32>,
    /// Longitude, 1e-7 degrees.
    pub lon_e7: Option<i32>,
    /// Speed over ground, cm/s.
    pub speed_cm_s: Option<u16>,
    /// Course over ground, hundredths of a degree.
    pub course_cdeg: Option<u16>,
    /// Altitude above mean sea level, cm.
    pub alt_cm: Option<i32>,
    /// Satellites used.
    pub sats: Option<u8>,
    /// HDOP, tenths.
    pub hdop_d: Option<u8>,
    /// The sentence stated an HDOP the record cannot hold (negative, not a
    /// number, or over 25.4): `hdop_d` is left unknown, never clamped, and
    /// the GPS path counts a fault.
    pub hdop_out_of_range: bool,
    /// Validity of the fix this sentence reports.
    pub validity: Validity,
    /// The 2D/3D mode a GSA states.
    pub gsa_mode: Option<FixMode>,
}

/// The outcome of classifying and parsing one valid line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Sentence {
    /// A sentence of a merged type, parsed.
    Update(Kind, Update),
    /// A sentence this logger does not use (GSV, TXT, `$P...`): skipped.
    Ignored,
    /// A sentence of a merged type that the `nmea` crate rejected.
    Unparseable(Kind),
    /// A sentence of a merged type with a field no receiver can mean: a
    /// position off the globe, minutes of 60 or more, an absurd speed,
    /// altitude or satellite count. None of its fields are used.
    OutOfRange(Kind),
}

/// Classifies and parses `text`, a complete line `$...*hh` whose checksum
/// has been verified.
#[must_use]
pub fn parse(text: &str) -> Sentence {
    let address = text
        .get(1..)
        .and_then(|rest| rest.split([',', '*']).next())
        .unwrap_or("");
    // Proprietary sentences are `$P` + vendor; standard ones are a two-letter
    // talker (GP, GN, GL, GA, BD, GB, ...) and a three-letter type.
    if address.starts_with('P') || address.len() != 5 {
        return Sentence::Ignored;
    }
    let Some(kind) = address.get(2..).and_then(Kind::from_type) else {
        return Sentence::Ignored;
    };
    // The crate refuses 23:59:60; a leap second is parsed as :59 and the
    // second added back.
    let leap = leap_second_as_59(text, kind);
    let parsed = leap.as_ref().map_or(text, |l| l.as_str());
    let update = match nmea::parse_str(parsed) {
        Ok(ParseResult::RMC(d)) => from_rmc(&d),
        Ok(ParseResult::GGA(d)) => from_gga(&d),
        Ok(ParseResult::GLL(d)) => from_gll(&d),
        Ok(ParseResult::VTG(d)) => from_vtg(&d),
        Ok(ParseResult::GSA(d)) => from_gsa(&d),
        Ok(ParseResult::ZDA(d)) => from_zda(&d),
        _ => None,
    };
    match update {
        Some(_) if !minutes_in_range(text, kind) => Sentence::OutOfRange(kind),
        Some(u) if !in_range(&u) => Sentence::OutOfRange(kind),
        Some(mut u) => {
            if leap.is_some() {
                u.tod_ms = u.tod_ms.map(|ms| ms + 1000);
            }
            Sentence::Update(kind, u)
        }
        None => Sentence::Unparseable(kind),
    }
}

/// Whether every field of `u` is one a receiver can mean (the card format's
/// limits; conversions saturate, so absurd inputs land outside them).
fn in_range(u: &Update) -> bool {
    let position = match (u.lat_e7, u.lon_e7) {
        (Some(lat), Some(lon)) => limits::position_is_valid(lat, lon),
        (None, None) => true,
        _ => false,
    };
    position
        && u.speed_cm_s.is_none_or(|v| v <= SPEED_CM_S_MAX)
        && u.alt_cm.is_none_or(limits::altitude_is_valid)
        && u.sats.is_none_or(|n| n <= SATS_MAX)
}

/// Fields (after the address) of the latitude and longitude.
const fn position_fields(kind: Kind) -> Option<(usize, usize)> {
    match kind {
        Kind::Rmc => Some((3, 5)),
        Kind::Gga => Some((2, 4)),
        Kind::Gll => Some((1, 3)),
        _ => None,
    }
}

/// Whether the minutes of the sentence's latitude and longitude
/// (`ddmm.mmmm`, `dddmm.mmmm`) are below 60: the crate adds them to the
/// degrees as they come.
fn minutes_in_range(text: &str, kind: Kind) -> bool {
    let Some((lat, lon)) = position_fields(kind) else {
        return true;
    };
    let ok = |field: &str| {
        let whole = field.find('.').unwrap_or(field.len());
        field.is_empty()
            || field
                .get(whole.saturating_sub(2)..)
                .and_then(|m| m.parse::<f32>().ok())
                .is_some_and(|m| m < 60.0)
    };
    let body = text.split('*').next().unwrap_or("");
    let mut fields = body.split(',');
    let lat_field = fields.nth(lat).unwrap_or("");
    let lon_field = fields.nth(lon - lat - 1).unwrap_or("");
    ok(lat_field) && ok(lon_field)
}

/// Field (after the address) holding the UTC time `hhmmss.sss`.
const fn time_field(kind: Kind) -> Option<usize> {
    match kind {
        Kind::Rmc | Kind::Gga | Kind::Zda => Some(1),
        Kind::Gll => Some(5),
        _ => None,
    }
}

/// A line at most this long: the longest NMEA allows.
type Line = heapless::String<{ super::line::MAX_LINE }>;

/// The sentence with a leap second `23:59:60` written as `23:59:59` and its
/// checksum recomputed; `None` when its time is not a leap second.
fn leap_second_as_59(text: &str, kind: Kind) -> Option<Line> {
    let index = time_field(kind)?;
    let (body, _) = text.get(1..)?.split_once('*')?;
    let time = body.split(',').nth(index)?;
    if time.get(..6) != Some("235960") {
        return None;
    }
    let mut out = Line::new();
    out.push('$').ok()?;
    for (i, field) in body.split(',').enumerate() {
        if i > 0 {
            out.push(',').ok()?;
        }
        if i == index {
            out.push_str("235959").ok()?;
            out.push_str(field.get(6..)?).ok()?;
        } else {
            out.push_str(field).ok()?;
        }
    }
    let sum = out.bytes().skip(1).fold(0u8, |a, b| a ^ b);
    let hex = |n: u8| char::from(b"0123456789ABCDEF"[usize::from(n & 0xF)]);
    for c in ['*', hex(sum >> 4), hex(sum)] {
        out.push(c).ok()?;
    }
    Some(out)
}

fn from_rmc(d: &RmcData) -> Option<Update> {
    let valid = !matches!(
        d.status_of_fix,
        nmea::sentences::rmc::RmcStatusOfFix::Invalid
    );
    let date_days = match d.fix_date {
        Some(date) => Some(date_days(date)?),
        None => None,
    };
    Some(Update {
        tod_ms: d.fix_time.map(tod_ms),
        date_days,
        lat_e7: d.lat.map(deg_e7),
        lon_e7: d.lon.map(deg_e7),
        speed_cm_s: d.speed_over_ground.and_then(knots_to_cm_s),
        course_cdeg: d.true_course.and_then(course_cdeg),
        validity: if valid {
            Validity::Valid
        } else {
            Validity::Invalid
        },
        ..Update::default()
    })
}

fn from_gga(d: &GgaData) -> Option<Update> {
    let validity = match d.fix_type {
        Some(t) if t.is_valid() => Validity::Valid,
        Some(FixType::Invalid) | Some(_) => Validity::Invalid,
        None => Validity::Unknown,
    };
    Some(Update {
        tod_ms: d.fix_time.map(tod_ms),
        lat_e7: d.latitude.map(deg_e7),
        lon_e7: d.longitude.map(deg_e7),
        // NaN or infinite altitudes land outside the limits (not at 0 m).
        alt_cm: d.altitude.map(|m| {
            if m.is_finite() {
                quantise_i32(f64::from(m), 100.0)
            } else {
                i32::MIN
            }
        }),
        sats: d.fix_satellites.map(|n| n.min(u32::from(u8::MAX)) as u8),
        hdop_d: d.hdop.and_then(hdop_d),
        hdop_out_of_range: d.hdop.is_some_and(|h| hdop_d(h).is_none()),
        validity,
        ..Update::default()
    })
}

fn from_gll(d: &GllData) -> Option<Update> {
    Some(Update {
        tod_ms: d.fix_time.map(tod_ms),
        lat_e7: d.latitude.map(deg_e7),
        lon_e7: d.longitude.map(deg_e7),
        validity: if d.valid {
            Validity::Valid
        } else {
            Validity::Invalid
        },
        ..Update::default()
    })
}

fn from_vtg(d: &VtgData) -> Option<Update> {
    Some(Update {
        speed_cm_s: d.speed_over_ground.and_then(knots_to_cm_s),
        course_cdeg: d.true_course.and_then(course_cdeg),
        ..Update::default()
    })
}

fn from_gsa(d: &GsaData) -> Option<Update> {
    use nmea::sentences::gsa::GsaMode2;
    Some(Update {
        hdop_d: d.hdop.and_then(hdop_d),
        hdop_out_of_range: d.hdop.is_some_and(|h| hdop_d(h).is_none()),
        gsa_mode: Some(match d.mode2 {
            GsaMode2::NoFix => FixMode::None,
            GsaMode2::Fix2D => FixMode::Fix2d,
            GsaMode2::Fix3D => FixMode::Fix3d,
        }),
        ..Update::default()
    })
}

fn from_zda(d: &ZdaData) -> Option<Update> {
    let date_days = match d.utc_date() {
        Some(date) => Some(date_days(date)?),
        None => None,
    };
    Some(Update {
        tod_ms: d.utc_time.map(tod_ms),
        date_days,
        ..Update::default()
    })
}

fn tod_ms(t: chrono::NaiveTime) -> u32 {
    use chrono::Timelike;
    // Truncating the nanoseconds keeps exactly the digits the receiver sent
    // (the crate rounds its parse to the nanosecond).
    t.num_seconds_from_midnight() * 1000 + t.nanosecond() / 1_000_000
}

/// `None` (the sentence is unusable) for dates the record cannot hold: the
/// crate maps two-digit years 83-99 to the 1900s, which is what receivers
/// without a fix send from their RTC.
fn date_days(d: chrono::NaiveDate) -> Option<u16> {
    use chrono::Datelike;
    UtcTime::days_from_date(d.year(), d.month(), d.day())
}

fn deg_e7(deg: f64) -> i32 {
    quantise_i32(deg, 1e7)
}

fn knots_to_cm_s(knots: f32) -> Option<u16> {
    let cm_s = f64::from(knots) * MPS_PER_KNOT * 100.0;
    (cm_s.is_finite() && cm_s >= 0.0)
        .then(|| quantise_i32(cm_s, 1.0).clamp(0, i32::from(u16::MAX)) as u16)
}

/// A course of 360.00 deg (some receivers send it) is north, stored as 0:
/// the card format's courses are below 360 deg.
fn course_cdeg(deg: f32) -> Option<u16> {
    let cdeg = f64::from(deg) * 100.0;
    (cdeg.is_finite() && (0.0..=36_000.0).contains(&cdeg))
        .then(|| (quantise_i32(cdeg, 1.0) % i32::from(limits::COURSE_CDEG_END)) as u16)
}

/// HDOP in tenths, `None` when the record cannot hold it.
fn hdop_d(hdop: f32) -> Option<u8> {
    let hdop = f64::from(hdop);
    if !hdop.is_finite() || hdop < 0.0 {
        return None;
    }
    u8::try_from(quantise_i32(hdop, 10.0))
        .ok()
        .filter(|&d| d <= limits::HDOP_D_MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn update(text: &str) -> (Kind, Update) {
        match parse(text) {
            Sentence::Update(k, u) => (k, u),
            other => panic!("{text}: {other:?}"),
        }
    }

    #[test]
    fn rmc_fields() {
        let (kind, u) = update(
            "$GPRMC,132820.60,A,4134.49821229,N,09345.03351845,W,3.252,92.308,180320,11.5985,E,D*1A",
        );
        assert_eq!(kind, Kind::Rmc);
        assert_eq!(u.tod_ms, Some(((13 * 60 + 28) * 60 + 20) * 1000 + 600));
        assert_eq!(u.date_days, UtcTime::days_from_date(2020, 3, 18));
        assert_eq!(u.lat_e7, Some(415_749_702));
        assert_eq!(u.lon_e7, Some(-937_505_586));
        assert_eq!(u.speed_cm_s, Some(167)); // 3.252 kn = 1.6730 m/s
        assert_eq!(u.course_cdeg, Some(9231));
        assert_eq!(u.validity, Validity::Valid);
    }

    #[test]
    fn gga_fields_any_talker() {
        let (kind, u) =
            update("$GNGGA,055234.200,4739.71890,N,12219.58362,W,1,14,0.9,76.5,M,-21.6,M,,*4A");
        assert_eq!(kind, Kind::Gga);
        assert_eq!(u.alt_cm, Some(7650));
        assert_eq!(u.sats, Some(14));
        assert_eq!(u.hdop_d, Some(9));
        assert_eq!(u.validity, Validity::Valid);
    }

    /// `body` as a sentence with its checksum.
    fn sealed(body: &str) -> String {
        let sum = body.bytes().fold(0u8, |a, b| a ^ b);
        format!("${body}*{sum:02X}")
    }

    #[test]
    fn a_nan_altitude_is_out_of_range_not_sea_level() {
        let text = sealed("GNGGA,055234.200,4739.71890,N,12219.58362,W,1,14,0.9,NaN,M,-21.6,M,,");
        match parse(&text) {
            Sentence::OutOfRange(Kind::Gga) | Sentence::Unparseable(Kind::Gga) => {}
            other => panic!("{text}: {other:?}"),
        }
    }

    #[test]
    fn a_course_of_360_is_north() {
        let (_, u) = update(&sealed(
            "GPRMC,132820.60,A,4134.49821229,N,09345.03351845,W,3.252,360.00,180320,11.5985,E,D",
        ));
        assert_eq!(u.course_cdeg, Some(0));
        let (_, u) = update(&sealed(
            "GPRMC,132820.60,A,4134.49821229,N,09345.03351845,W,3.252,359.99,180320,11.5985,E,D",
        ));
        assert_eq!(u.course_cdeg, Some(35_999));
    }

    #[test]
    fn gga_quality_zero_is_invalid() {
        let (_, u) =
            update("$GPGGA,081434.590,5212.978993,N,00653.097906,E,0,3,,102.907,M,47.093,M,,*42");
        assert_eq!(u.validity, Validity::Invalid);
        assert_eq!(u.hdop_d, None);
    }

    #[test]
    fn rmc_status_v_is_invalid() {
        // A receiver without a fix sends its RTC's date (here "80", which the
        // crate reads as 2080) and a stale position: the V status is what
        // keeps them out of the fix.
        let (_, u) =
            update("$GPRMC,235946.005,V,5213.000000,N,00653.000000,E,0.000,0.00,050180,,,N*45");
        assert_eq!(u.validity, Validity::Invalid);
        // The MTK-3301's power-up placeholder, 89 deg 60 min, is no position.
        assert_eq!(
            parse("$GPRMC,235946.005,V,8960.000000,N,00000.000000,E,0.000,0.00,050180,,,N*47"),
            Sentence::OutOfRange(Kind::Rmc)
        );
    }

    #[test]
    fn gsa_vtg_zda_gll() {
        let (_, gsa) = update("$GNGSA,A,3,02,07,14,15,17,20,22,30,,,,,1.5,0.9,1.2,1*3C");
        assert_eq!(gsa.gsa_mode, Some(FixMode::Fix3d));
        assert_eq!(gsa.hdop_d, Some(9));
        let (_, vtg) = update("$GPVTG,0.00,T,,M,0.052,N,0.097,K,N*3B");
        assert_eq!(vtg.speed_cm_s, Some(3));
        assert_eq!(vtg.course_cdeg, Some(0));
        let (_, zda) = update("$GNZDA,055234.000,05,08,2026,00,00*46");
        assert_eq!(zda.date_days, UtcTime::days_from_date(2026, 8, 5));
        assert_eq!(zda.tod_ms, Some(((5 * 60 + 52) * 60 + 34) * 1000));
        let (_, gll) = update("$GNGLL,4739.71890,N,12219.58362,W,055234.200,A,A*5F");
        assert_eq!(gll.validity, Validity::Valid);
        assert_eq!(gll.tod_ms, Some(((5 * 60 + 52) * 60 + 34) * 1000 + 200));
    }

    #[test]
    fn unused_and_proprietary_sentences_are_ignored() {
        for s in [
            "$GPGSV,3,1,11,02,60,319,36,05,77,132,38,11,29,052,29,12,46,186,46*74",
            "$PGRME,7.6,M,41.7,M,42.4,M*2F",
            "$GPTXT,01,01,01,ANTENNA OK*35",
            "$PMTK010,001*2E",
        ] {
            assert_eq!(parse(s), Sentence::Ignored, "{s}");
        }
    }

    #[test]
    fn rejected_by_the_crate_is_unparseable() {
        // Valid checksum, but "X" is no RMC status.
        assert_eq!(parse("$GPRMC,1,X*22"), Sentence::Unparseable(Kind::Rmc));
    }
}
