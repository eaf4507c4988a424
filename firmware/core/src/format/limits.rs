//! What the firmware can write: the ranges inside which a record's values
//! lie. A CRC only says a block is as written; a value outside these ranges
//! says the writer (a bug, a glitch, a crafted file) was wrong. The decoder
//! drops such values and counts them; the GPS path counts NMEA fields
//! outside them as faults and never records them.

use super::record::{GpsFix, LogInfo, UtcSync, UtcTime};

/// Latitude limit, 1e-7 degrees.
pub const LAT_E7_MAX: i32 = 900_000_000;
/// Longitude limit, 1e-7 degrees.
pub const LON_E7_MAX: i32 = 1_800_000_000;
/// Milliseconds in a UTC day that ends with a leap second (23:59:60.999 is
/// the last valid time).
pub const DAY_MS_WITH_LEAP: u32 = 86_401_000;
/// First day not representable by NMEA's two-digit years: 2100-01-01.
pub const UTC_DAYS_END: u16 = 36_525;
/// Course over ground limit, 0.01 degrees (exclusive: 360 deg is 0 deg).
pub const COURSE_CDEG_END: u16 = 36_000;
/// Fastest speed over ground a receiver reports, cm/s: the export-control
/// limit of civil GNSS receivers (1000 knots, 514 m/s).
pub const SPEED_CM_S_MAX: u16 = 51_444;
/// Altitude range, cm: from below the Dead Sea shore to the civil-receiver
/// ceiling of 18 km.
pub const ALT_CM_RANGE: (i32, i32) = (-50_000, 1_800_000);
/// Most satellites an NMEA GGA sentence can state (two digits).
pub const SATS_MAX: u8 = 99;
/// Largest HDOP the record holds, tenths (0xFF is "unknown").
pub const HDOP_D_MAX: u8 = 254;
/// Sample rates the logger can be configured to, Hz.
pub const SAMPLE_RATE_HZ_RANGE: (u16, u16) = (1, 1000);
/// The documented frame rate, used when a log states an impossible one.
pub const DEFAULT_SAMPLE_RATE_HZ: u16 = 100;
/// UTC sync range, ms since the Unix epoch: 2000-01-01 to 2100-01-01.
pub const UNIX_MS_RANGE: (u64, u64) = (946_684_800_000, 4_102_444_800_000);

impl UtcTime {
    /// Whether this is a real UTC date and time of day in the years NMEA
    /// can state. A leap second (23:59:60) is valid only at the end of a
    /// month that can end with one: June or December first, March or
    /// September second (ITU-R TF.460-6); every leap second so far has
    /// ended June or December.
    #[must_use]
    pub fn is_valid(self) -> bool {
        if self.days_since_2000 >= UTC_DAYS_END || self.ms_of_day >= DAY_MS_WITH_LEAP {
            return false;
        }
        if self.ms_of_day < DAY_MS_WITH_LEAP - 1000 {
            return true;
        }
        let (year, month, day) = self.date();
        matches!(month, 3 | 6 | 9 | 12) && day == super::record::days_in_month(year, month)
    }
}

impl UtcSync {
    /// Whether the UTC it states is in the years NMEA can state.
    #[must_use]
    pub const fn is_valid(&self) -> bool {
        UNIX_MS_RANGE.0 <= self.unix_ms && self.unix_ms < UNIX_MS_RANGE.1
    }
}

impl LogInfo<'_> {
    /// Whether the sample rate is one the logger can run at.
    #[must_use]
    pub const fn sample_rate_is_valid(&self) -> bool {
        SAMPLE_RATE_HZ_RANGE.0 <= self.sample_rate_hz
            && self.sample_rate_hz <= SAMPLE_RATE_HZ_RANGE.1
    }
}

/// Whether a position is on the globe.
#[must_use]
pub const fn position_is_valid(lat_e7: i32, lon_e7: i32) -> bool {
    lat_e7.unsigned_abs() <= LAT_E7_MAX.unsigned_abs()
        && lon_e7.unsigned_abs() <= LON_E7_MAX.unsigned_abs()
}

/// Whether an altitude is one a civil receiver reports.
#[must_use]
pub const fn altitude_is_valid(alt_cm: i32) -> bool {
    ALT_CM_RANGE.0 <= alt_cm && alt_cm <= ALT_CM_RANGE.1
}

impl GpsFix {
    /// Removes every field outside what the GPS path writes; returns how
    /// many were removed. A fix whose position goes loses its 2D/3D mode.
    pub fn drop_out_of_range(&mut self) -> u32 {
        let mut dropped = 0;
        let mut keep = |ok: bool| {
            dropped += u32::from(!ok);
            ok
        };
        self.utc = self.utc.filter(|u| keep(u.is_valid()));
        if let (Some(lat), Some(lon)) = (self.lat_e7, self.lon_e7) {
            if !keep(position_is_valid(lat, lon)) {
                (self.lat_e7, self.lon_e7) = (None, None);
                self.fix = super::record::FixMode::None;
            }
        }
        self.speed_cm_s = self.speed_cm_s.filter(|&v| keep(v <= SPEED_CM_S_MAX));
        self.course_cdeg = self.course_cdeg.filter(|&v| keep(v < COURSE_CDEG_END));
        self.alt_cm = self.alt_cm.filter(|&v| keep(altitude_is_valid(v)));
        self.sats = self.sats.filter(|&v| keep(v <= SATS_MAX));
        dropped
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::FixMode;

    #[test]
    fn a_leap_second_is_valid_only_where_one_can_be() {
        let day = |y, m, d| UtcTime::days_from_date(y, m, d).unwrap();
        let leap = |days_since_2000| UtcTime {
            days_since_2000,
            ms_of_day: 86_400_500,
        };
        // 2016-12-31 and 2015-06-30 had one; 2026-02-14 and 2016-12-30 cannot.
        assert!(leap(day(2016, 12, 31)).is_valid());
        assert!(leap(day(2015, 6, 30)).is_valid());
        assert!(!leap(day(2026, 2, 14)).is_valid());
        assert!(!leap(day(2016, 12, 30)).is_valid());
        assert!(UtcTime {
            days_since_2000: day(2026, 2, 14),
            ms_of_day: 86_399_999,
        }
        .is_valid());
    }

    #[test]
    fn dates_the_month_does_not_have_are_none() {
        assert_eq!(UtcTime::days_from_date(2026, 2, 30), None);
        assert_eq!(UtcTime::days_from_date(2026, 2, 29), None);
        assert!(UtcTime::days_from_date(2024, 2, 29).is_some());
        assert_eq!(UtcTime::days_from_date(2100, 2, 29), None);
        assert_eq!(UtcTime::days_from_date(2026, 4, 31), None);
        assert_eq!(
            UtcTime::days_from_date(2026, 3, 1),
            UtcTime::days_from_date(2026, 2, 28).map(|d| d + 1)
        );
    }

    #[test]
    fn a_leap_second_is_a_valid_utc_time_but_24_00_is_not_a_day_of_its_own() {
        let t = |ms_of_day| UtcTime {
            days_since_2000: UtcTime::days_from_date(2016, 12, 31).unwrap(),
            ms_of_day,
        };
        assert!(t(86_400_500).is_valid());
        assert!(!t(86_401_000).is_valid());
        assert!(!t(4_294_967_295).is_valid());
        assert!(!UtcTime {
            days_since_2000: UTC_DAYS_END,
            ms_of_day: 0
        }
        .is_valid());
    }

    #[test]
    fn values_off_the_globe_or_absurd_are_dropped_and_counted() {
        let mut fix = GpsFix {
            lat_e7: Some(914_748_364),
            lon_e7: Some(68_800_000),
            speed_cm_s: Some(u16::MAX),
            course_cdeg: Some(36_000),
            alt_cm: Some(2_147_483_647),
            sats: Some(255),
            fix: FixMode::Fix3d,
            ..GpsFix::default()
        };
        assert_eq!(fix.drop_out_of_range(), 5);
        assert_eq!(fix.lat_e7, None);
        assert_eq!(fix.fix, FixMode::None);
        let mut good = GpsFix {
            lat_e7: Some(-900_000_000),
            lon_e7: Some(1_800_000_000),
            speed_cm_s: Some(400),
            course_cdeg: Some(35_999),
            alt_cm: Some(-42_000),
            sats: Some(12),
            fix: FixMode::Fix3d,
            ..GpsFix::default()
        };
        let before = good;
        assert_eq!(good.drop_out_of_range(), 0);
        assert_eq!(good, before);
    }
}
