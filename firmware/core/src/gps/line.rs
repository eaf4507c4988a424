//! NMEA line assembly: UART bytes in arbitrary chunks -> checksummed lines.
//!
//! The assembler is a three-state machine over single bytes, so it neither
//! cares how the UART driver chunks its data nor ever waits for more than one
//! byte. Every `$` starts a new line whatever state the machine is in, which
//! is what makes resynchronisation unconditional: after any amount of garbage,
//! truncated or overlong lines, the next complete sentence is assembled
//! correctly. The buffer is fixed ([`MAX_LINE`] bytes); nothing allocates.

/// Longest line kept, from `$` through the checksum digits, without CR/LF.
///
/// NMEA 0183 allows 82 characters including CR/LF, but real receivers exceed
/// it (the Trimble capture has 91-character GGA). This is the `nmea` crate's
/// own limit, so every line the assembler passes on is one the crate accepts.
pub const MAX_LINE: usize = nmea::SENTENCE_MAX_LEN;

/// Why a line was dropped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LineError {
    /// The `*hh` checksum did not match, or its two hex digits were corrupt.
    Checksum,
    /// The line ended without a `*hh` checksum field.
    NoChecksum,
    /// No line end within [`MAX_LINE`] bytes of the `$`.
    Overlong,
    /// A byte that cannot occur in NMEA text (control or non-ASCII byte), or a
    /// new `$` before the line ended: bytes were lost or corrupted on the wire.
    Framing,
}

/// What the assembler produced from one byte.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LineEvent<'a> {
    /// A complete line whose checksum matched.
    Valid {
        /// The line from `$` through the checksum digits: printable ASCII.
        text: &'a str,
        /// Local time at which its `$` arrived, µs since boot.
        t_us: u64,
    },
    /// A line that was dropped.
    Rejected {
        /// Why.
        error: LineError,
        /// The line was a proprietary sentence (`$P...`), which NMEA exempts
        /// from the rules on length and, by vendors' habit, on checksums.
        proprietary: bool,
        /// Local time at which its `$` arrived, µs since boot.
        t_us: u64,
    },
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    /// Between lines: waiting for `$`.
    Hunt,
    /// Inside a line, collecting bytes into the buffer.
    Line,
    /// Inside an overlong line: waiting for its end (or a new `$`).
    Skip,
}

/// Turns a byte stream into NMEA lines (see the module docs).
#[derive(Clone, Debug)]
pub struct LineAssembler {
    buf: [u8; MAX_LINE],
    len: usize,
    state: State,
    t_start_us: u64,
}

impl Default for LineAssembler {
    fn default() -> Self {
        Self::new()
    }
}

impl LineAssembler {
    /// An assembler waiting for the first `$`.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            buf: [0; MAX_LINE],
            len: 0,
            state: State::Hunt,
            t_start_us: 0,
        }
    }

    /// Feeds one byte received at local time `t_us`.
    pub fn push(&mut self, byte: u8, t_us: u64) -> Option<LineEvent<'_>> {
        if byte == b'$' {
            // A `$` always starts a line; one that interrupts a line in
            // progress means the tail of that line was lost.
            let interrupted = self.state == State::Line;
            let event = interrupted.then(|| self.reject(LineError::Framing));
            self.buf[0] = b'$';
            self.len = 1;
            self.state = State::Line;
            self.t_start_us = t_us;
            return event;
        }
        match self.state {
            State::Hunt => None,
            State::Skip => {
                if byte == b'\r' || byte == b'\n' {
                    self.state = State::Hunt;
                }
                None
            }
            State::Line => {
                if byte == b'\r' || byte == b'\n' {
                    self.state = State::Hunt;
                    return Some(self.finish());
                }
                if !(0x20..=0x7e).contains(&byte) {
                    self.state = State::Hunt;
                    return Some(self.reject(LineError::Framing));
                }
                if self.len == MAX_LINE {
                    self.state = State::Skip;
                    return Some(self.reject(LineError::Overlong));
                }
                self.buf[self.len] = byte;
                self.len += 1;
                None
            }
        }
    }

    fn reject(&self, error: LineError) -> LineEvent<'static> {
        LineEvent::Rejected {
            error,
            proprietary: self.len > 1 && self.buf[1] == b'P',
            t_us: self.t_start_us,
        }
    }

    /// Checks the collected line `$body*hh`.
    fn finish(&self) -> LineEvent<'_> {
        let line = &self.buf[..self.len];
        let Some(star) = line.iter().rposition(|&b| b == b'*') else {
            return self.reject(LineError::NoChecksum);
        };
        let expected = match line[star + 1..] {
            [hi, lo] => hex_digit(hi).zip(hex_digit(lo)).map(|(h, l)| h << 4 | l),
            _ => None,
        };
        let actual = line[1..star].iter().fold(0u8, |acc, &b| acc ^ b);
        if expected != Some(actual) {
            return self.reject(LineError::Checksum);
        }
        match core::str::from_utf8(line) {
            Ok(text) => LineEvent::Valid {
                text,
                t_us: self.t_start_us,
            },
            // Unreachable: only printable ASCII enters the buffer. Treated as
            // corruption rather than a panic all the same.
            Err(_) => self.reject(LineError::Framing),
        }
    }
}

fn hex_digit(b: u8) -> Option<u8> {
    match b {
        b'0'..=b'9' => Some(b - b'0'),
        b'A'..=b'F' => Some(b - b'A' + 10),
        b'a'..=b'f' => Some(b - b'a' + 10),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const RMC: &[u8] = b"$GPRMC,113258,A,3238.9148,N,10822.4466,W,005.3,247.1,181022,009.3,E*6B";

    /// A valid line and its start time, or a rejection, its proprietary flag
    /// and its start time.
    type Out = Result<(String, u64), (LineError, bool, u64)>;

    /// Feeds `bytes` (byte i at t = i µs) and collects what came out.
    fn run(bytes: &[u8]) -> Vec<Out> {
        let mut asm = LineAssembler::new();
        let mut out = Vec::new();
        for (i, &b) in bytes.iter().enumerate() {
            match asm.push(b, i as u64) {
                Some(LineEvent::Valid { text, t_us }) => out.push(Ok((text.to_owned(), t_us))),
                Some(LineEvent::Rejected {
                    error,
                    proprietary,
                    t_us,
                }) => out.push(Err((error, proprietary, t_us))),
                None => {}
            }
        }
        out
    }

    fn with_crlf(line: &[u8]) -> Vec<u8> {
        [line, b"\r\n"].concat()
    }

    #[test]
    fn valid_line_with_crlf_lf_or_cr() {
        for end in [&b"\r\n"[..], b"\n", b"\r"] {
            let out = run(&[RMC, end].concat());
            assert_eq!(out, [Ok((String::from_utf8(RMC.to_vec()).unwrap(), 0))]);
        }
    }

    #[test]
    fn timestamp_is_that_of_the_dollar() {
        let out = run(&[&b"xx\r\n"[..], &with_crlf(RMC)].concat());
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].as_ref().unwrap().1, 4);
    }

    #[test]
    fn lowercase_checksum_digits_are_accepted() {
        let line = b"$GPRMC,113258,A,3238.9148,N,10822.4466,W,005.3,247.1,181022,009.3,E*6b";
        assert!(run(&with_crlf(line))[0].is_ok());
    }

    /// Every checksum a line can have, so every digit in either case: the
    /// XOR of the bytes between `$` and `*` (NMEA 0183; ASCII, so 0 to
    /// 0x7f), written in upper or lower case, is accepted; one off is not.
    #[test]
    fn every_checksum_reads_in_either_case() {
        let prefix = b"GPTXT,";
        let c = prefix.iter().fold(0u8, |a, &b| a ^ b);
        for sum in 0..0x80u8 {
            // Two digits or letters that make the line's XOR `sum`.
            let (x, y) = (b'0'..=b'z')
                .flat_map(|x| (b'0'..=b'z').map(move |y| (x, y)))
                .find(|&(x, y)| c ^ x ^ y == sum)
                .expect("a pair");
            let body = format!("GPTXT,{}{}", char::from(x), char::from(y));
            for text in [format!("${body}*{sum:02X}"), format!("${body}*{sum:02x}")] {
                assert!(run(&with_crlf(text.as_bytes()))[0].is_ok(), "{text}");
            }
            let wrong = format!("${body}*{:02x}", sum ^ 1);
            assert_eq!(
                run(&with_crlf(wrong.as_bytes())),
                [Err((LineError::Checksum, false, 0))],
                "{wrong}"
            );
        }
    }

    #[test]
    fn checksum_errors() {
        let mut bad = RMC.to_vec();
        bad[10] = b'9';
        assert_eq!(
            run(&with_crlf(&bad)),
            [Err((LineError::Checksum, false, 0))]
        );
        let truncated = &RMC[..RMC.len() - 1];
        assert_eq!(
            run(&with_crlf(truncated)),
            [Err((LineError::Checksum, false, 0))]
        );
        let not_hex = b"$GPTXT,x*G1";
        assert_eq!(
            run(&with_crlf(not_hex)),
            [Err((LineError::Checksum, false, 0))]
        );
    }

    #[test]
    fn missing_checksum_is_reported_with_the_proprietary_flag() {
        assert_eq!(
            run(b"$STI,IC,error=4\r\n"),
            [Err((LineError::NoChecksum, false, 0))]
        );
        assert_eq!(
            run(b"$POLYN,TIME,RESTART_OCCURRED\r\n"),
            [Err((LineError::NoChecksum, true, 0))]
        );
    }

    /// A line that is only its `$` is no proprietary sentence, whatever
    /// the line before it left in the buffer.
    #[test]
    fn a_bare_dollar_is_not_proprietary_after_a_proprietary_line() {
        let out = run(b"$POLYN,TIME\r\n$\r\n");
        assert_eq!(
            out,
            [
                Err((LineError::NoChecksum, true, 0)),
                Err((LineError::NoChecksum, false, 13))
            ]
        );
    }

    #[test]
    fn overlong_line_is_dropped_and_the_next_one_parsed() {
        let mut long = b"$PMTKCHN,".to_vec();
        long.resize(300, b'1');
        let input = [with_crlf(&long), with_crlf(RMC)].concat();
        let out = run(&input);
        assert_eq!(out.len(), 2);
        assert_eq!(out[0], Err((LineError::Overlong, true, 0)));
        assert!(out[1].is_ok());
    }

    #[test]
    fn longest_line_fits() {
        // Build a line of exactly MAX_LINE bytes with a valid checksum.
        let mut body = b"GPTXT,".to_vec();
        body.resize(MAX_LINE - 4, b'A');
        let cs = body.iter().fold(0u8, |a, &b| a ^ b);
        let line = format!("${}*{cs:02X}", String::from_utf8(body).unwrap());
        assert_eq!(line.len(), MAX_LINE);
        assert!(run(&with_crlf(line.as_bytes()))[0].is_ok());
        let longer = line.replace("GPTXT,", "GPTXT,A");
        assert_eq!(
            run(&with_crlf(longer.as_bytes()))[0],
            Err((LineError::Overlong, false, 0))
        );
    }

    #[test]
    fn dollar_inside_a_line_resynchronises() {
        let input = [&b"$GPGGA,1234"[..], &with_crlf(RMC)].concat();
        let out = run(&input);
        assert_eq!(out[0], Err((LineError::Framing, false, 0)));
        assert_eq!(out[1].as_ref().unwrap().1, 11);
    }

    #[test]
    fn control_bytes_abort_the_line() {
        let input = [&b"$GPGGA,12\x0034"[..], &with_crlf(RMC)].concat();
        let out = run(&input);
        assert_eq!(out[0], Err((LineError::Framing, false, 0)));
        assert!(out[1].is_ok());
        assert_eq!(out.len(), 2);
    }

    #[test]
    fn garbage_between_lines_is_silent() {
        let input = [&b"\xff\xfe junk \n\r\n"[..], &with_crlf(RMC), b"\x00\x01"].concat();
        assert_eq!(run(&input).len(), 1);
    }

    #[test]
    fn empty_line_has_no_checksum() {
        assert_eq!(run(b"$\r\n"), [Err((LineError::NoChecksum, false, 0))]);
    }
}
