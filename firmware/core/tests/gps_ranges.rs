//! NMEA fields no receiver can mean are counted faults, never data; a leap
//! second is a valid UTC second.

use proptest::prelude::*;
use wobble_core::format::{GpsFix, UtcTime};
use wobble_core::gps::sentence::{self, Kind, Sentence};
use wobble_core::gps::{GpsConfig, GpsEvent, GpsReceiver, FAULT_OUT_OF_RANGE};

/// `$body*hh` with its checksum.
fn line(body: &str) -> String {
    let sum = body.bytes().fold(0u8, |a, b| a ^ b);
    format!("${body}*{sum:02X}")
}

fn rmc(time: &str, lat: &str, lon: &str, knots: &str) -> String {
    line(&format!(
        "GPRMC,{time},A,{lat},N,{lon},E,{knots},84.4,230324,,,A"
    ))
}

fn gga(time: &str, lat: &str, lon: &str, sats: &str, alt: &str) -> String {
    gga_hdop(time, lat, lon, sats, "0.9", alt)
}

fn gga_hdop(time: &str, lat: &str, lon: &str, sats: &str, hdop: &str, alt: &str) -> String {
    line(&format!(
        "GPGGA,{time},{lat},N,{lon},E,1,{sats},{hdop},{alt},M,46.9,M,,"
    ))
}

/// The fixes `lines` give through the GPS path (one epoch per line pair,
/// a second apart), and its count of fault 6.
fn through_receiver(lines: &[String]) -> (Vec<GpsFix>, u32) {
    let mut rx = GpsReceiver::new(GpsConfig::default());
    let mut fixes = Vec::new();
    let mut t_us = 0;
    let mut keep = |e: GpsEvent| {
        if let GpsEvent::Fix(f) = e {
            fixes.push(f);
        }
    };
    for text in lines {
        for b in text.bytes().chain(*b"\r\n") {
            t_us += 100;
            rx.push_byte(b, t_us, &mut keep);
        }
        t_us += 1_000_000;
    }
    rx.finish(t_us + 5_000_000, &mut keep);
    (
        fixes,
        rx.stats().faults[usize::from(FAULT_OUT_OF_RANGE) - 1],
    )
}

fn update(text: &str) -> sentence::Update {
    match sentence::parse(text) {
        Sentence::Update(_, u) => u,
        other => panic!("{text}: {other:?}"),
    }
}

#[test]
fn fields_outside_what_a_receiver_can_mean_are_out_of_range() {
    let ok = update(&rmc("123519", "4807.038", "01131.000", "22.4"));
    assert_eq!(ok.lat_e7, Some(481_173_000));
    for bad in [
        rmc("123519", "9100.000", "01131.000", "22.4"),
        rmc("123519", "4807.038", "18100.000", "22.4"),
        rmc("123519", "4899.9999", "01131.000", "22.4"),
        rmc("123519", "4807.038", "01160.000", "22.4"),
        rmc("123519", "4807.038", "01131.000", "1000000000"),
        gga("123519", "4807.038", "01131.000", "999", "545.4"),
        gga("123519", "4807.038", "01131.000", "08", "1000000000"),
        gga("123519", "9000.001", "01131.000", "08", "545.4"),
    ] {
        assert!(
            matches!(sentence::parse(&bad), Sentence::OutOfRange(_)),
            "{bad}: {:?}",
            sentence::parse(&bad)
        );
    }
    // The poles and the antimeridian are on the globe.
    let pole = update(&gga("123519", "9000.000", "18000.000", "08", "545.4"));
    assert_eq!(
        (pole.lat_e7, pole.lon_e7),
        (Some(900_000_000), Some(1_800_000_000))
    );
}

#[test]
fn a_leap_second_is_the_sixty_first_second_of_the_minute() {
    for text in [
        rmc("235960.50", "4807.038", "01131.000", "22.4"),
        gga("235960.50", "4807.038", "01131.000", "08", "545.4"),
        line("GPGLL,4807.038,N,01131.000,E,235960.50,A,A"),
        line("GPZDA,235960.50,31,12,2016,00,00"),
    ] {
        assert_eq!(update(&text).tod_ms, Some(86_400_500), "{text}");
    }
    // Second 60 of any other minute is not a time.
    assert!(matches!(
        sentence::parse(&rmc("123560", "4807.038", "01131.000", "22.4")),
        Sentence::Unparseable(Kind::Rmc)
    ));
}

#[test]
fn an_hdop_the_record_cannot_hold_is_unknown_and_counted_not_clamped() {
    let hdop = |h: &str| {
        update(&gga_hdop(
            "123519",
            "4807.038",
            "01131.000",
            "08",
            h,
            "545.4",
        ))
    };
    assert_eq!(hdop("25.4").hdop_d, Some(254));
    assert!(!hdop("25.4").hdop_out_of_range);
    assert_eq!(hdop("0.0").hdop_d, Some(0));
    for bad in ["25.5", "99.99", "-1.0", "1e30"] {
        let u = hdop(bad);
        assert_eq!((u.hdop_d, u.hdop_out_of_range), (None, true), "HDOP {bad}");
        assert_eq!(
            u.lat_e7,
            Some(481_173_000),
            "HDOP {bad}: the position stays"
        );
    }
    let gsa = update(&line("GPGSA,A,3,02,05,11,12,,,,,,,,,99.9,99.99,99.9"));
    assert_eq!((gsa.hdop_d, gsa.hdop_out_of_range), (None, true));
    // Through the GPS path: a counted fault, and a fix with its position.
    let rmc_line = rmc("123519", "4807.038", "01131.000", "22.4");
    let bad = gga_hdop("123519", "4807.038", "01131.000", "08", "99.99", "545.4");
    let (fixes, faults) = through_receiver(&[rmc_line.clone(), bad]);
    assert_eq!(faults, 1);
    assert_eq!(fixes.len(), 1);
    assert_eq!(
        (fixes[0].hdop_d, fixes[0].lat_e7),
        (None, Some(481_173_000))
    );
    let good = gga_hdop("123519", "4807.038", "01131.000", "08", "1.3", "545.4");
    let (fixes, faults) = through_receiver(&[rmc_line, good]);
    assert_eq!((faults, fixes[0].hdop_d), (0, Some(13)));
}

#[test]
fn a_leap_second_is_kept_where_the_calendar_has_one_and_counted_elsewhere() {
    let rmc_on = |date: &str| {
        line(&format!(
            "GPRMC,235960.50,A,4807.038,N,01131.000,E,22.4,84.4,{date},,,A"
        ))
    };
    // 31 December 2016 ended with a leap second.
    let (fixes, faults) = through_receiver(&[rmc_on("311216")]);
    assert_eq!(faults, 0);
    assert_eq!(
        fixes[0].utc,
        Some(UtcTime {
            days_since_2000: UtcTime::days_from_date(2016, 12, 31).unwrap(),
            ms_of_day: 86_400_500,
        })
    );
    // 23 March 2024 cannot: a counted fault, the fix without its UTC (not
    // moved to :59, nor to the next day).
    let (fixes, faults) = through_receiver(&[rmc_on("230324")]);
    assert_eq!(faults, 1);
    assert_eq!(fixes.len(), 1);
    assert_eq!((fixes[0].utc, fixes[0].lat_e7), (None, Some(481_173_000)));
}

proptest! {
    /// Whatever latitude and longitude digits a sentence holds, what it
    /// gives is on the globe, or a counted fault when it is not.
    #[test]
    fn positions_are_on_the_globe_or_refused(
        lat_deg in 0u32..100, lat_min in 0.0f64..100.0,
        lon_deg in 0u32..400, lon_min in 0.0f64..100.0,
    ) {
        let text = rmc(
            "123519",
            &format!("{lat_deg:02}{lat_min:07.4}"),
            &format!("{lon_deg:03}{lon_min:07.4}"),
            "1.0",
        );
        let valid = lat_min < 60.0 && lon_min < 60.0
            && f64::from(lat_deg) + lat_min / 60.0 <= 90.0
            && f64::from(lon_deg) + lon_min / 60.0 <= 180.0;
        match sentence::parse(&text) {
            Sentence::Update(_, u) => {
                prop_assert!(valid, "{text}: {u:?}");
                prop_assert!(u.lat_e7.unwrap().unsigned_abs() <= 900_000_000);
                prop_assert!(u.lon_e7.unwrap().unsigned_abs() <= 1_800_000_000);
            }
            // Both are counted faults (the crate itself refuses some).
            Sentence::OutOfRange(_) | Sentence::Unparseable(_) => prop_assert!(!valid, "{text}"),
            other => prop_assert!(false, "{text}: {other:?}"),
        }
    }
}
