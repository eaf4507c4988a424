//! NMEA fields no receiver can mean are counted faults, never data; a leap
//! second is a valid UTC second.

use proptest::prelude::*;
use wobble_core::gps::sentence::{self, Kind, Sentence};

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
    line(&format!(
        "GPGGA,{time},{lat},N,{lon},E,1,{sats},0.9,{alt},M,46.9,M,,"
    ))
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
