//! The receiver set-up commands carry the checksums the receivers check:
//! compared with sentences and frames published in the vendors' manuals.

use wobble_core::drivers::gnss_setup::{
    baud_commands, nmea, rate_commands, ubx, valset_command, MAX_COMMAND_LEN,
};

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

#[test]
fn valset_sets_rate_sentences_and_baud_in_ram() {
    let cmd = valset_command();
    assert!(cmd.len() <= MAX_COMMAND_LEN);
    // UBX-CFG-VALSET, version 0, RAM layer.
    assert_eq!(cmd[2..4], [0x06, 0x8A]);
    let len = usize::from(u16::from_le_bytes([cmd[4], cmd[5]]));
    assert_eq!(cmd.len(), len + 8);
    let payload = &cmd[6..6 + len];
    assert_eq!(payload[..4], [0, 1, 0, 0]);
    // Key-value pairs; the value size is the key's bits 30:28 (1: 1 bit
    // stored as a byte, 2: 1 byte, 3: 2 bytes, 4: 4 bytes).
    let mut items = Vec::new();
    let mut rest = &payload[4..];
    while !rest.is_empty() {
        let key = u32::from_le_bytes(rest[..4].try_into().unwrap());
        let size = match (key >> 28) & 0x7 {
            1 | 2 => 1,
            3 => 2,
            4 => 4,
            other => panic!("size code {other}"),
        };
        let mut value = [0u8; 4];
        value[..size].copy_from_slice(&rest[4..4 + size]);
        items.push((key, u32::from_le_bytes(value)));
        rest = &rest[4 + size..];
    }
    assert_eq!(
        items,
        [
            (0x3021_0001, 50),
            (0x2091_00AC, 1),
            (0x2091_00BB, 1),
            (0x2091_00CA, 0),
            (0x2091_00C0, 0),
            (0x2091_00C5, 0),
            (0x2091_00B1, 0),
            (0x4052_0001, 115_200),
        ]
    );
}
