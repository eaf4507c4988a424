//! Loading gpsd's captures (hil-tests/fixtures/gps) for the GPS tests.

use std::path::PathBuf;

/// Synthetic clock: byte `i` of a capture arrives at `i * BYTE_US`, the
/// character time of 100 000 baud (close to the receiver's 115 200, and an
/// integer so chunked and byte-wise feeding give identical timestamps).
pub const BYTE_US: u64 = 100;

/// The baud rate whose character time is [`BYTE_US`].
pub const BAUD: u32 = 100_000;

/// The captures with a gpsd `.chk` file.
#[allow(dead_code)] // not every test file uses every helper
pub const CAPTURES: [&str; 6] = [
    "bu353s4.log",
    "garmin15x.log",
    "mtk-3301.log",
    "nmea-fuzzy-cases.log",
    "quectel-l76k-nmea.log",
    "skytraq-err.log",
];

/// A capture as the wire carried it.
pub struct Capture {
    /// The bytes fed to the receiver: the capture without its `#` lines.
    pub bytes: Vec<u8>,
    /// Each line (with its line end) as a byte range of `bytes`.
    pub lines: Vec<std::ops::Range<usize>>,
}

impl Capture {
    /// Line `i` without its line end.
    #[allow(dead_code)] // not every test file uses every helper
    pub fn text(&self, i: usize) -> String {
        String::from_utf8_lossy(&self.bytes[self.lines[i].clone()])
            .trim_end()
            .to_owned()
    }
}

/// The fixture directory.
pub fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../hil-tests/fixtures/gps")
}

/// Reads capture `name`, dropping gpsd's `#` comment lines.
pub fn load(name: &str) -> Capture {
    let raw = std::fs::read(dir().join(name)).expect("capture readable");
    let mut bytes = Vec::new();
    let mut lines = Vec::new();
    for line in raw.split_inclusive(|&b| b == b'\n') {
        if !line.starts_with(b"#") {
            lines.push(bytes.len()..bytes.len() + line.len());
            bytes.extend_from_slice(line);
        }
    }
    Capture { bytes, lines }
}
