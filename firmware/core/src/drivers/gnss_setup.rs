//! Boot-time commands that ask common GNSS receivers for what the logger
//! wants: 115 200 baud, 20 Hz fixes, only RMC and GGA sentences.
//!
//! Three dialects cover most receivers on small boards: MediaTek's `PMTK`
//! NMEA sentences, u-blox's legacy UBX CFG-PRT/RATE/MSG messages (up to
//! M8), and UBX-CFG-VALSET for the M9/M10 generation, which dropped the
//! legacy ones. The legacy set carries both the MTK and the UBX commands
//! (each receiver ignores the other's): [`baud_commands`] at the baud the
//! receiver talks at, then [`rate_commands`] at 115 200; [`valset_command`]
//! is one message at the receiver's baud. A receiver that cannot do 20 Hz
//! rejects the rate and keeps its own: the GPS path copes with any rate.
//! Which set to send, and whether it worked, is decided by
//! [`super::gnss_bringup`].

use heapless::Vec;

/// Longest command built here, bytes.
pub const MAX_COMMAND_LEN: usize = 64;
/// One command, ready for the UART.
pub type Command = Vec<u8, MAX_COMMAND_LEN>;

/// The logger's GPS baud rate.
pub const TARGET_BAUD: u32 = 115_200;
/// Fix interval asked for: 50 ms, 20 Hz.
pub const FIX_INTERVAL_MS: u16 = 50;

/// UBX message class CFG.
const UBX_CFG: u8 = 0x06;
/// UBX-CFG-PRT: port configuration.
const UBX_CFG_PRT: u8 = 0x00;
/// UBX-CFG-MSG: message rate.
const UBX_CFG_MSG: u8 = 0x01;
/// UBX-CFG-RATE: navigation rate.
const UBX_CFG_RATE: u8 = 0x08;
/// UBX-CFG-VALSET: set configuration items (M9/M10).
const UBX_CFG_VALSET: u8 = 0x8A;
/// CFG-VALSET layer bit: RAM only (the setting is lost at power-off, so a
/// receiver shared with other equipment is left as it was).
const VALSET_LAYER_RAM: u8 = 0x01;
/// Configuration keys (u-blox M10 interface description): baud rate of
/// UART1 (U4), measurement period in ms (U2), and the UART1 output rate of
/// each NMEA sentence (U1, per epoch).
const KEY_UART1_BAUDRATE: u32 = 0x4052_0001;
const KEY_RATE_MEAS: u32 = 0x3021_0001;
const KEY_MSGOUT_NMEA_UART1: [(u32, bool); 6] = [
    (0x2091_00AC, true),  // RMC
    (0x2091_00BB, true),  // GGA
    (0x2091_00CA, false), // GLL
    (0x2091_00C0, false), // GSA
    (0x2091_00C5, false), // GSV
    (0x2091_00B1, false), // VTG
];
/// UBX class of the standard NMEA sentences, and their ids.
const NMEA_CLASS: u8 = 0xF0;
const NMEA_GGA: u8 = 0x00;
const NMEA_GLL: u8 = 0x01;
const NMEA_GSA: u8 = 0x02;
const NMEA_GSV: u8 = 0x03;
const NMEA_RMC: u8 = 0x04;
const NMEA_VTG: u8 = 0x05;
/// CFG-PRT mode word: 8 data bits, no parity, 1 stop bit.
const UART_MODE_8N1: u32 = 0x0000_08D0;
/// CFG-PRT protocol masks: UBX (bit 0) and NMEA (bit 1), in and out.
const PROTO_UBX_NMEA: u16 = 0x0003;

/// An NMEA sentence `$body*hh\r\n` with its XOR checksum.
#[must_use]
pub fn nmea(body: &str) -> Command {
    let checksum = body.bytes().fold(0u8, |acc, b| acc ^ b);
    let mut out = Command::new();
    let mut hex = [0u8; 2];
    for (digit, shift) in hex.iter_mut().zip([4, 0]) {
        *digit = b"0123456789ABCDEF"[usize::from((checksum >> shift) & 0xF)];
    }
    // Only this module's short constant bodies are passed in.
    let _ = out.push(b'$');
    let _ = out.extend_from_slice(body.as_bytes());
    let _ = out.push(b'*');
    let _ = out.extend_from_slice(&hex);
    let _ = out.extend_from_slice(b"\r\n");
    out
}

/// A UBX frame: sync, class, id, little-endian length, payload, and the
/// 8-bit Fletcher checksum over class..payload.
#[must_use]
pub fn ubx(class: u8, id: u8, payload: &[u8]) -> Command {
    let mut out = Command::new();
    let len = u16::try_from(payload.len())
        .unwrap_or(u16::MAX)
        .to_le_bytes();
    let _ = out.extend_from_slice(&[0xB5, 0x62, class, id, len[0], len[1]]);
    let _ = out.extend_from_slice(payload);
    let (mut ck_a, mut ck_b) = (0u8, 0u8);
    for &b in out.get(2..).unwrap_or_default() {
        ck_a = ck_a.wrapping_add(b);
        ck_b = ck_b.wrapping_add(ck_a);
    }
    let _ = out.extend_from_slice(&[ck_a, ck_b]);
    out
}

/// Switch the receiver's UART to [`TARGET_BAUD`]: MTK, then u-blox UART1.
#[must_use]
pub fn baud_commands() -> [Command; 2] {
    let mut prt = [0u8; 20];
    prt[0] = 1; // port 1: UART1
    prt[4..8].copy_from_slice(&UART_MODE_8N1.to_le_bytes());
    prt[8..12].copy_from_slice(&TARGET_BAUD.to_le_bytes());
    prt[12..14].copy_from_slice(&PROTO_UBX_NMEA.to_le_bytes());
    prt[14..16].copy_from_slice(&PROTO_UBX_NMEA.to_le_bytes());
    [nmea("PMTK251,115200"), ubx(UBX_CFG, UBX_CFG_PRT, &prt)]
}

/// 20 Hz fixes with only RMC and GGA: MTK fix interval and sentence mask,
/// then u-blox measurement rate and one CFG-MSG per sentence.
#[must_use]
pub fn rate_commands() -> [Command; 9] {
    let [ms_lo, ms_hi] = FIX_INTERVAL_MS.to_le_bytes();
    // measRate, navRate 1, timeRef 1 (GPS time).
    let rate = [ms_lo, ms_hi, 1, 0, 1, 0];
    let msg = |id: u8, on: bool| ubx(UBX_CFG, UBX_CFG_MSG, &[NMEA_CLASS, id, u8::from(on)]);
    [
        nmea("PMTK220,50"),
        // Field order: GLL, RMC, VTG, GGA, GSA, GSV, ..., 1 = every fix.
        nmea("PMTK314,0,1,0,1,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0"),
        ubx(UBX_CFG, UBX_CFG_RATE, &rate),
        msg(NMEA_RMC, true),
        msg(NMEA_GGA, true),
        msg(NMEA_GLL, false),
        msg(NMEA_GSA, false),
        msg(NMEA_GSV, false),
        msg(NMEA_VTG, false),
    ]
}

/// One UBX-CFG-VALSET (RAM layer) with everything at once: 20 Hz, RMC and
/// GGA only, then 115 200 baud (applied after the message).
#[must_use]
pub fn valset_command() -> Command {
    let mut payload: Vec<u8, 56> = Vec::new();
    // version 0, layers, 2 reserved bytes.
    let _ = payload.extend_from_slice(&[0, VALSET_LAYER_RAM, 0, 0]);
    let _ = payload.extend_from_slice(&KEY_RATE_MEAS.to_le_bytes());
    let _ = payload.extend_from_slice(&FIX_INTERVAL_MS.to_le_bytes());
    for (key, on) in KEY_MSGOUT_NMEA_UART1 {
        let _ = payload.extend_from_slice(&key.to_le_bytes());
        let _ = payload.push(u8::from(on));
    }
    let _ = payload.extend_from_slice(&KEY_UART1_BAUDRATE.to_le_bytes());
    let _ = payload.extend_from_slice(&TARGET_BAUD.to_le_bytes());
    ubx(UBX_CFG, UBX_CFG_VALSET, &payload)
}
