//! Reading what a run left on the card, through the host tools' library
//! (the same reader `wobblog` uses).

use std::path::Path;

use wobble_core::format::{
    Alert, DecodeStats, Dropout, Event, Fault, Frame, GpsFix, KickRingDown, MarginRecord, Record,
};
use wobblog::summary::{Summary, SummaryBuilder};

use super::card;

/// One decoded log file.
#[derive(Clone, Debug)]
pub struct Log {
    /// File name on the card.
    pub name: String,
    /// Frames, in file order.
    pub frames: Vec<Frame>,
    /// GPS fixes.
    pub fixes: Vec<GpsFix>,
    /// Alert records.
    pub alerts: Vec<Alert>,
    /// Dropout records.
    pub dropouts: Vec<Dropout>,
    /// Fault records.
    pub faults: Vec<Fault>,
    /// Kick ring-down records.
    pub kicks: Vec<KickRingDown>,
    /// Margin warning records.
    pub margins: Vec<MarginRecord>,
    /// Whether the first record is the log info header.
    pub starts_with_header: bool,
    /// The decoder's totals.
    pub stats: DecodeStats,
    /// The `wobblog info` summary.
    pub summary: Summary,
}

/// Decodes every `RUN*.WBL` file on the card image, in name order. Each
/// file is copied out under `work_dir` first.
///
/// # Errors
/// The image is not FAT, or a log has no valid block at all.
pub fn logs(image: &Path, work_dir: &Path) -> Result<Vec<Log>, String> {
    let mut files = card::root_files(image)?;
    files.retain(|(name, _)| name.starts_with("RUN") && name.ends_with(".WBL"));
    files.sort();
    files
        .into_iter()
        .map(|(name, data)| decode_file(&name, &data, work_dir))
        .collect()
}

fn decode_file(name: &str, data: &[u8], work_dir: &Path) -> Result<Log, String> {
    let path = work_dir.join(name);
    std::fs::write(&path, data).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut log = Log {
        name: name.to_owned(),
        frames: Vec::new(),
        fixes: Vec::new(),
        alerts: Vec::new(),
        dropouts: Vec::new(),
        faults: Vec::new(),
        kicks: Vec::new(),
        margins: Vec::new(),
        starts_with_header: false,
        stats: DecodeStats::default(),
        summary: Summary::default(),
    };
    let mut builder = SummaryBuilder::new();
    let mut first = true;
    let stats = wobblog::reader::read_log(&path, |ev| {
        builder.observe(&ev);
        let Event::Record(rec) = ev else { return };
        if first {
            log.starts_with_header = matches!(rec, Record::LogInfo(_));
            first = false;
        }
        match rec {
            Record::Frame(f) => log.frames.push(f),
            Record::Gps(g) => log.fixes.push(g),
            Record::Alert(a) => log.alerts.push(a),
            Record::Dropout(d) => log.dropouts.push(d),
            Record::Fault(f) => log.faults.push(f),
            Record::Kick(k) => log.kicks.push(k),
            Record::Margin(m) => log.margins.push(m),
            _ => {}
        }
    })
    .map_err(|e| format!("{name}: {e}"))?;
    log.summary = builder.finish(&stats);
    log.stats = stats;
    Ok(log)
}
