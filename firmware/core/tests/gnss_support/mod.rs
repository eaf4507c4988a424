//! A simulated GPS receiver for the bring-up tests: MediaTek, u-blox M8
//! (legacy UBX), u-blox M10 (CFG-VALSET only) or deaf to every command. It
//! sends real NMEA sentences at its own baud and rate (limited by what the
//! baud can carry); bytes read at another baud arrive as garbage, and
//! commands sent at another baud are lost.

#![allow(dead_code)] // each test binary uses its own part of the model

pub mod link;

/// `$body*hh\r\n` (the set-up module's `nmea` holds only short commands).
pub fn nmea(body: &str) -> Vec<u8> {
    let checksum = body.bytes().fold(0u8, |acc, b| acc ^ b);
    format!("${body}*{checksum:02X}\r\n").into_bytes()
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Family {
    /// PMTK commands.
    Mtk,
    /// u-blox M8: legacy UBX CFG messages.
    UbloxM8,
    /// u-blox M10: CFG-VALSET only.
    UbloxM10,
    /// NMEA out, deaf to every command.
    Deaf,
}

#[derive(Clone, Debug)]
pub struct Receiver {
    pub family: Family,
    pub baud: u32,
    pub rate_hz: u32,
    pub max_rate_hz: u32,
    /// Only RMC and GGA (else also GSA and GSV, as out of the box).
    pub lean: bool,
    /// Listening windows during which it is still booting (silent).
    pub booting: u32,
    /// Noise instead of sentences, at every baud.
    pub noise: bool,
    pub silent: bool,
    /// Deterministic noise generator state.
    pub seed: u64,
    /// Epochs sent so far by [`Receiver::transmit_timed`] (each has its
    /// own UTC time).
    pub epochs_sent: u32,
}

impl Receiver {
    pub fn new(family: Family, baud: u32) -> Self {
        Self {
            family,
            baud,
            rate_hz: 1,
            max_rate_hz: 20,
            lean: false,
            booting: 0,
            noise: false,
            silent: false,
            seed: 0x9E37_79B9_7F4A_7C15,
            epochs_sent: 0,
        }
    }

    pub fn noise_byte(&mut self) -> u8 {
        self.seed ^= self.seed << 13;
        self.seed ^= self.seed >> 7;
        self.seed ^= self.seed << 17;
        (self.seed >> 24) as u8
    }

    /// One epoch's sentences.
    pub fn epoch(&self, k: u32) -> Vec<u8> {
        let t = format!("1232{:02}.{:02}", k / 20 % 60, k % 20 * 5);
        let mut out = nmea(&format!(
            "GPRMC,{t},A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W"
        ));
        out.extend(nmea(&format!(
            "GPGGA,{t},4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"
        )));
        if !self.lean {
            out.extend(nmea("GPGSA,A,3,04,05,,09,12,,,24,,,,,2.5,1.3,2.1"));
            out.extend(nmea(
                "GPGSV,2,1,08,01,40,083,46,02,17,308,41,12,07,344,39,14,22,228,45",
            ));
        }
        out
    }

    /// What the UART at `baud` receives during `for_us`.
    pub fn transmit(&mut self, baud: u32, for_us: u64) -> Vec<u8> {
        if self.silent {
            return Vec::new();
        }
        if self.booting > 0 {
            self.booting -= 1;
            return Vec::new();
        }
        let line_bytes_per_s = u64::from(self.baud / 10);
        let mut out = Vec::new();
        if self.noise {
            let n = (u64::from(baud / 10) * for_us / 1_000_000) as usize;
            return (0..n).map(|_| self.noise_byte()).collect();
        }
        // The rate is what the line can carry.
        let epoch_len = self.epoch(0).len() as u64;
        let rate = u64::from(self.rate_hz)
            .min(line_bytes_per_s / epoch_len)
            .max(1);
        let epochs = rate * for_us / 1_000_000;
        for k in 0..epochs {
            out.extend(self.epoch(k as u32));
        }
        if baud == self.baud {
            out
        } else {
            // Sampled at the wrong baud: as many bytes, none of them text.
            let n = out.len() * baud as usize / self.baud as usize;
            (0..n).map(|_| self.noise_byte() | 0x80).collect()
        }
    }

    /// What the UART at `baud` receives during `for_us`, each byte with the
    /// time its stop bit ends, µs from the start: each epoch's burst starts
    /// on the receiver's epoch clock and goes out back to back at its baud;
    /// read at another baud, the same stretch of line is as many bytes of
    /// the UART's own baud, none of them text.
    pub fn transmit_timed(&mut self, baud: u32, for_us: u64) -> Vec<(u64, u8)> {
        if self.silent {
            return Vec::new();
        }
        if self.booting > 0 {
            self.booting -= 1;
            return Vec::new();
        }
        let char_ns = |baud: u32| 10_000_000_000 / u64::from(baud);
        if self.noise {
            let n = u64::from(baud / 10) * for_us / 1_000_000;
            return (1..=n)
                .map(|i| (i * char_ns(baud) / 1000, self.noise_byte()))
                .collect();
        }
        let epoch_len = self.epoch(0).len() as u64;
        let rate = u64::from(self.rate_hz)
            .min(u64::from(self.baud / 10) / epoch_len)
            .max(1);
        let mut out = Vec::new();
        for k in 0..rate * for_us / 1_000_000 {
            let start_ns = k * 1_000_000_000 / rate;
            let bytes = self.epoch(self.epochs_sent);
            self.epochs_sent += 1;
            if baud == self.baud {
                out.extend(
                    (1..)
                        .zip(bytes)
                        .map(|(i, b)| ((start_ns + i * char_ns(baud)) / 1000, b)),
                );
            } else {
                let n = bytes.len() as u64 * u64::from(baud) / u64::from(self.baud);
                for i in 1..=n {
                    let b = self.noise_byte() | 0x80;
                    out.push(((start_ns + i * char_ns(baud)) / 1000, b));
                }
            }
        }
        out
    }

    /// Applies one command received at `baud`.
    pub fn receive(&mut self, baud: u32, cmd: &[u8]) {
        if baud != self.baud || self.silent || self.noise || self.booting > 0 {
            return;
        }
        let text = std::str::from_utf8(cmd).unwrap_or("");
        match self.family {
            Family::Mtk => {
                if let Some(b) = text.strip_prefix("$PMTK251,") {
                    self.baud = b.split('*').next().unwrap().parse().unwrap();
                } else if text.starts_with("$PMTK220,50*") {
                    self.rate_hz = 20.min(self.max_rate_hz);
                } else if text.starts_with("$PMTK314,0,1,0,1,0,0,") {
                    self.lean = true;
                }
            }
            Family::UbloxM8 => match (cmd.first(), cmd.get(2..4)) {
                (Some(0xB5), Some([0x06, 0x00])) => {
                    self.baud = u32::from_le_bytes(cmd[14..18].try_into().unwrap());
                }
                (Some(0xB5), Some([0x06, 0x08])) => {
                    let ms = u32::from(u16::from_le_bytes([cmd[6], cmd[7]]));
                    self.rate_hz = (1000 / ms).min(self.max_rate_hz);
                }
                // CFG-MSG for GSV off (the last of the GSA/GSV pair sent).
                (Some(0xB5), Some([0x06, 0x01])) if cmd[7] == 0x03 && cmd[8] == 0 => {
                    self.lean = true;
                }
                _ => {}
            },
            Family::UbloxM10 => {
                if cmd.first() == Some(&0xB5) && cmd.get(2..4) == Some(&[0x06, 0x8A]) {
                    // Rate (first item) and baud (last item), see gnss_setup.
                    let ms = u32::from(u16::from_le_bytes([cmd[14], cmd[15]]));
                    self.rate_hz = (1000 / ms).min(self.max_rate_hz);
                    self.lean = true;
                    let n = cmd.len();
                    self.baud = u32::from_le_bytes(cmd[n - 6..n - 2].try_into().unwrap());
                }
            }
            Family::Deaf => {}
        }
    }
}
