//! The receiver set-up commands carry the checksums the receivers check:
//! compared with sentences and frames published in the vendors' manuals.

use wobble_core::drivers::gnss_setup::{baud_commands, nmea, rate_commands, ubx};

#[test]
fn nmea_checksums_match_published_pmtk_sentences() {
    assert_eq!(nmea("PMTK220,100").as_slice(), b"$PMTK220,100*2F\r\n");
    assert_eq!(nmea("PMTK251,115200").as_slice(), b"$PMTK251,115200*1F\r\n");
    assert_eq!(
        nmea("PMTK314,0,1,0,1,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0").as_slice(),
        b"$PMTK314,0,1,0,1,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0*28\r\n"
    );
}

#[test]
fn ubx_checksum_matches_the_published_10hz_rate_frame() {
    let frame = ubx(0x06, 0x08, &[0x64, 0x00, 0x01, 0x00, 0x01, 0x00]);
    assert_eq!(
        frame.as_slice(),
        [0xB5, 0x62, 0x06, 0x08, 0x06, 0x00, 0x64, 0x00, 0x01, 0x00, 0x01, 0x00, 0x7A, 0x12]
    );
}

#[test]
fn boot_commands_ask_for_115200_baud_and_20hz_rmc_gga() {
    let [mtk_baud, ubx_prt] = baud_commands();
    assert_eq!(mtk_baud.as_slice(), b"$PMTK251,115200*1F\r\n");
    // CFG-PRT, 20-byte payload: UART1, 8N1, 115200 baud.
    assert_eq!(ubx_prt[2..6], [0x06, 0x00, 20, 0]);
    assert_eq!(ubx_prt[6], 1);
    assert_eq!(ubx_prt[14..18], 115_200u32.to_le_bytes());
    let rates = rate_commands();
    assert!(rates[0].starts_with(b"$PMTK220,50*"));
    // CFG-RATE: 50 ms measurement period.
    assert_eq!(rates[2][6..8], [50, 0]);
    // CFG-MSG: RMC and GGA on, the others off.
    let msg = |c: &[u8]| (c[7], c[8]);
    let settings: Vec<_> = rates[3..].iter().map(|c| msg(c)).collect();
    assert_eq!(settings, [(4, 1), (0, 1), (1, 0), (2, 0), (3, 0), (5, 0)]);
    for cmd in rates.iter().skip(2).chain([&ubx_prt]) {
        let body = &cmd[2..cmd.len() - 2];
        let (mut a, mut b) = (0u8, 0u8);
        for &x in body {
            a = a.wrapping_add(x);
            b = b.wrapping_add(a);
        }
        assert_eq!(cmd[cmd.len() - 2..], [a, b]);
    }
}
