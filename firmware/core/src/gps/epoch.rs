//! Merging the sentences of one receiver epoch into one [`GpsFix`].
//!
//! # The epoch rule
//!
//! A receiver reports each navigation solution (epoch) as a burst of
//! sentences: some carry the UTC time of the fix (RMC, GGA, GLL, ZDA), some
//! do not (VTG, GSA). The merger keeps one open epoch:
//!
//! 1. A sentence whose UTC time of day differs from the open epoch's starts a
//!    new epoch; the open one is complete and emitted first.
//! 2. A sentence without a time joins the open epoch (or opens one that takes
//!    the time of the next timed sentence).
//! 3. The epoch is also complete, and emitted at once, when the sentence that
//!    closed the previous epochs arrives: the merger learns which sentence
//!    (type and occurrence, e.g. "the 3rd GSA") ended an epoch, and adopts it
//!    once two epochs in a row ended with it. This removes one epoch of
//!    latency without knowing the receiver model. Talkers (GP, GN, GL, BD...)
//!    are not part of the sentence identity.
//! 4. A timed sentence of the epoch just emitted (the learned closer was
//!    wrong) re-opens that epoch; it is emitted again, completed, and the
//!    closer is forgotten until it is learned again.
//! 5. An epoch is also emitted when [`EpochMerger::poll`] finds it older than
//!    the timeout (receiver stopped mid-burst) and on [`EpochMerger::flush`].
//!
//! # Fields and fix mode
//!
//! Each field takes the value of the last sentence in the epoch that carries
//! it. The mode is, in order: no fix if any sentence says so (RMC/GLL `V`,
//! GGA quality 0/6/7/8); else the highest GSA mode; else 3D from a valid GGA
//! with altitude and at least 4 satellites (3D needs 4), 2D from any other
//! valid GGA/RMC/GLL; else no fix. A 2D/3D mode also needs a position. A fix
//! without a 2D/3D mode keeps only satellites and HDOP: what receivers send
//! without a fix (placeholder positions such as 90°N, RTC dates) is noise.
//!
//! The date comes from the epoch's RMC or ZDA; an epoch without one takes the
//! date of the last valid fix, rolled over at midnight.

use super::sentence::{Kind, Update, Validity};
use crate::format::{FixMode, GpsFix, UtcTime};

/// Milliseconds in a day.
const DAY_MS: u32 = 86_400_000;

/// A sentence's identity within an epoch: its kind and how many of that kind
/// the epoch had when it arrived (1 for the first).
type Position = (Kind, u8);

#[derive(Clone, Copy, Debug)]
struct Epoch {
    t_us: u64,
    tod_ms: Option<u32>,
    fields: Update,
    any_invalid: bool,
    gga_valid: bool,
    rmc_or_gll_valid: bool,
    gsa_mode: Option<FixMode>,
    counts: [u8; Kind::COUNT],
    last: Option<Position>,
}

impl Epoch {
    fn new(t_us: u64) -> Self {
        Self {
            t_us,
            tod_ms: None,
            fields: Update::default(),
            any_invalid: false,
            gga_valid: false,
            rmc_or_gll_valid: false,
            gsa_mode: None,
            counts: [0; Kind::COUNT],
            last: None,
        }
    }

    fn merge(&mut self, kind: Kind, u: &Update) {
        let f = &mut self.fields;
        f.date_days = u.date_days.or(f.date_days);
        f.lat_e7 = u.lat_e7.or(f.lat_e7);
        f.lon_e7 = u.lon_e7.or(f.lon_e7);
        f.speed_cm_s = u.speed_cm_s.or(f.speed_cm_s);
        f.course_cdeg = u.course_cdeg.or(f.course_cdeg);
        f.alt_cm = u.alt_cm.or(f.alt_cm);
        f.sats = u.sats.or(f.sats);
        f.hdop_d = u.hdop_d.or(f.hdop_d);
        if self.tod_ms.is_none() {
            self.tod_ms = u.tod_ms;
        }
        match (kind, u.validity) {
            (_, Validity::Invalid) => self.any_invalid = true,
            (Kind::Gga, Validity::Valid) => self.gga_valid = true,
            (_, Validity::Valid) => self.rmc_or_gll_valid = true,
            (_, Validity::Unknown) => {}
        }
        if let Some(m) = u.gsa_mode {
            self.gsa_mode = Some(self.gsa_mode.map_or(m, |old| max_mode(old, m)));
        }
        let n = &mut self.counts[kind.index()];
        *n = n.saturating_add(1);
        self.last = Some((kind, *n));
    }

    fn mode(&self) -> FixMode {
        let f = &self.fields;
        let mode = if self.any_invalid {
            FixMode::None
        } else if let Some(m) = self.gsa_mode {
            m
        } else if self.gga_valid {
            if f.alt_cm.is_some() && f.sats.is_none_or(|n| n >= 4) {
                FixMode::Fix3d
            } else {
                FixMode::Fix2d
            }
        } else if self.rmc_or_gll_valid {
            FixMode::Fix2d
        } else {
            FixMode::None
        };
        if f.lat_e7.is_some() && f.lon_e7.is_some() {
            mode
        } else {
            FixMode::None
        }
    }
}

fn max_mode(a: FixMode, b: FixMode) -> FixMode {
    let rank = |m| match m {
        FixMode::None => 0,
        FixMode::Fix2d => 1,
        FixMode::Fix3d => 2,
    };
    if rank(b) > rank(a) {
        b
    } else {
        a
    }
}

/// Merges sentence updates into fixes (see the module docs for the rule).
#[derive(Clone, Debug)]
pub struct EpochMerger {
    timeout_us: u64,
    open: Option<Epoch>,
    last_emitted: Option<Epoch>,
    closer: Option<Position>,
    candidate: Option<Position>,
    /// Date and time of day of the last valid fix.
    last_utc: Option<UtcTime>,
}

impl EpochMerger {
    /// A merger that emits an unfinished epoch `timeout_us` after its first
    /// sentence began.
    #[must_use]
    pub const fn new(timeout_us: u64) -> Self {
        Self {
            timeout_us,
            open: None,
            last_emitted: None,
            closer: None,
            candidate: None,
            last_utc: None,
        }
    }

    /// Merges the update of one sentence that began at `t_us`.
    pub fn push(&mut self, kind: Kind, update: &Update, t_us: u64, emit: &mut impl FnMut(GpsFix)) {
        self.poll(t_us, emit);
        if let Some(tod) = update.tod_ms {
            match &self.open {
                Some(open) if open.tod_ms.is_some_and(|t| t != tod) => {
                    let ended_with = open.last;
                    self.emit(emit);
                    self.learn(ended_with);
                }
                None => {
                    if let Some(done) = self.last_emitted.filter(|e| e.tod_ms == Some(tod)) {
                        self.open = Some(done);
                        self.closer = None;
                        self.candidate = None;
                    }
                }
                Some(_) => {}
            }
        }
        let open = self.open.get_or_insert_with(|| Epoch::new(t_us));
        open.merge(kind, update);
        if open.last.is_some() && open.last == self.closer {
            self.emit(emit);
        }
    }

    /// Emits the open epoch if it has been open longer than the timeout.
    pub fn poll(&mut self, now_us: u64, emit: &mut impl FnMut(GpsFix)) {
        if self
            .open
            .is_some_and(|e| now_us.saturating_sub(e.t_us) > self.timeout_us)
        {
            self.emit(emit);
        }
    }

    /// Emits the open epoch, complete or not (end of input).
    pub fn flush(&mut self, emit: &mut impl FnMut(GpsFix)) {
        self.emit(emit);
    }

    /// An epoch ended because the next one began: `ended_with` closed it.
    fn learn(&mut self, ended_with: Option<Position>) {
        if ended_with.is_some() && ended_with == self.candidate {
            self.closer = ended_with;
        }
        self.candidate = ended_with;
    }

    fn emit(&mut self, emit: &mut impl FnMut(GpsFix)) {
        let Some(epoch) = self.open.take() else {
            return;
        };
        self.last_emitted = Some(epoch);
        emit(self.fix(&epoch));
    }

    fn fix(&mut self, e: &Epoch) -> GpsFix {
        let f = &e.fields;
        let mode = e.mode();
        let mut fix = GpsFix {
            t_us: e.t_us,
            fix: mode,
            sats: f.sats,
            hdop_d: f.hdop_d,
            ..GpsFix::default()
        };
        if mode == FixMode::None {
            return fix;
        }
        fix.lat_e7 = f.lat_e7;
        fix.lon_e7 = f.lon_e7;
        fix.speed_cm_s = f.speed_cm_s;
        fix.course_cdeg = f.course_cdeg;
        fix.alt_cm = f.alt_cm;
        if let Some(tod) = e.tod_ms {
            let days = f.date_days.or_else(|| {
                let last = self.last_utc?;
                // Time of day going back by more than half a day is midnight.
                let rolled = tod < last.ms_of_day.saturating_sub(DAY_MS / 2);
                last.days_since_2000.checked_add(u16::from(rolled))
            });
            // A leap second on a day that cannot end with one is passed on
            // for the receiver to count and drop, but not taken as the
            // date of later fixes.
            fix.utc = days.map(|days_since_2000| UtcTime {
                days_since_2000,
                ms_of_day: tod,
            });
            if fix.utc.is_some_and(UtcTime::is_valid) {
                self.last_utc = fix.utc;
            }
        }
        fix
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gps::sentence::{parse, Sentence};

    fn checksummed(body: &str) -> String {
        let cs = body.bytes().fold(0u8, |a, b| a ^ b);
        format!("${body}*{cs:02X}")
    }

    /// Feeds lines (sentence i starting at t = i ms) and collects fixes.
    fn merge<S: AsRef<str>>(lines: &[S]) -> Vec<GpsFix> {
        let mut m = EpochMerger::new(1_500_000);
        let mut out = Vec::new();
        for (i, line) in lines.iter().enumerate() {
            if let Sentence::Update(kind, u) = parse(line.as_ref()) {
                m.push(kind, &u, i as u64 * 1000, &mut |f| out.push(f));
            }
        }
        m.flush(&mut |f| out.push(f));
        out
    }

    const GARMIN: [&str; 9] = [
        "$GPRMC,113258,A,3238.9148,N,10822.4466,W,005.3,247.1,181022,009.3,E*6B",
        "$GPGGA,113258,3238.9148,N,10822.4466,W,2,08,1.1,1577.4,M,-24.6,M,,*4D",
        "$GPGSA,A,3,02,05,11,12,18,20,25,29,,,,,1.4,1.1,0.9*3D",
        "$GPRMC,113259,A,3238.9145,N,10822.4482,W,005.0,246.3,181022,009.3,E*6D",
        "$GPGGA,113259,3238.9145,N,10822.4482,W,2,08,1.1,1577.9,M,-24.6,M,,*46",
        "$GPGSA,A,3,02,05,11,12,18,20,25,29,,,,,1.4,1.1,0.9*3D",
        "$GPRMC,113300,A,3238.9141,N,10822.4498,W,005.0,245.0,181022,009.3,E*6F",
        "$GPGGA,113300,3238.9141,N,10822.4498,W,2,08,1.1,1578.4,M,-24.6,M,,*46",
        "$GPGSA,A,3,02,05,11,12,18,20,25,29,,,,,1.4,1.1,0.9*3D",
    ];

    #[test]
    fn one_fix_per_epoch_with_merged_fields() {
        let fixes = merge(&GARMIN);
        assert_eq!(fixes.len(), 3);
        let f = fixes[0];
        assert_eq!(f.t_us, 0);
        assert_eq!(f.fix, FixMode::Fix3d);
        assert_eq!(f.alt_cm, Some(157_740));
        assert_eq!(f.speed_cm_s, Some(273)); // 5.3 kn
        assert_eq!(f.sats, Some(8));
        assert_eq!(f.hdop_d, Some(11));
        let utc = f.utc.unwrap();
        assert_eq!(utc.date(), (2022, 10, 18));
        assert_eq!(utc.ms_of_day, (11 * 3600 + 32 * 60 + 58) * 1000);
        assert_eq!(fixes[1].t_us, 3000);
        assert_eq!(fixes[2].t_us, 6000);
    }

    #[test]
    fn learned_closer_emits_without_waiting_for_the_next_epoch() {
        let mut m = EpochMerger::new(1_500_000);
        let mut out = Vec::new();
        let mut emitted_after = Vec::new();
        for (i, line) in GARMIN.iter().enumerate() {
            if let Sentence::Update(kind, u) = parse(line) {
                m.push(kind, &u, i as u64, &mut |f| out.push(f));
            }
            emitted_after.push(out.len());
        }
        // Epochs 1 and 2 end when the next begins; both ended with the GSA,
        // so epoch 3 is emitted on its GSA.
        assert_eq!(emitted_after, [0, 0, 0, 1, 1, 1, 2, 2, 3]);
    }

    #[test]
    fn late_sentence_reopens_the_epoch() {
        // Closer learned as the GGA; then an epoch whose RMC follows its GGA.
        let lines = [
            "$GPRMC,113258,A,3238.9148,N,10822.4466,W,005.3,247.1,181022,009.3,E*6B",
            "$GPGGA,113258,3238.9148,N,10822.4466,W,2,08,1.1,1577.4,M,-24.6,M,,*4D",
            "$GPRMC,113259,A,3238.9145,N,10822.4482,W,005.0,246.3,181022,009.3,E*6D",
            "$GPGGA,113259,3238.9145,N,10822.4482,W,2,08,1.1,1577.9,M,-24.6,M,,*46",
            "$GPGGA,113300,3238.9141,N,10822.4498,W,2,08,1.1,1578.4,M,-24.6,M,,*46",
            "$GPRMC,113300,A,3238.9141,N,10822.4498,W,005.0,245.0,181022,009.3,E*6F",
        ];
        let fixes = merge(&lines);
        // Epoch 113300 is emitted on its GGA (without speed), then again
        // complete after its late RMC.
        assert_eq!(fixes.len(), 4);
        assert_eq!(fixes[2].utc, fixes[3].utc);
        assert_eq!(fixes[2].speed_cm_s, None);
        assert_eq!(fixes[3].speed_cm_s, Some(257));
        assert_eq!(fixes[3].t_us, fixes[2].t_us);
    }

    #[test]
    fn invalid_epoch_keeps_no_position_or_time() {
        let fixes = merge(&[
            "$GPGGA,081434.590,5212.978993,N,00653.097906,E,0,3,,102.907,M,47.093,M,,*42",
            "$GPRMC,081434.590,V,5212.978993,N,00653.097906,E,0.052,0.00,230808,,,N*46",
        ]);
        assert_eq!(fixes.len(), 1);
        assert_eq!(
            fixes[0],
            GpsFix {
                t_us: 0,
                sats: Some(3),
                ..GpsFix::default()
            }
        );
    }

    #[test]
    fn mode_from_gga_needs_four_satellites_for_3d() {
        let three = merge(&[
            "$GPGGA,081436.000,5212.982135,N,00653.101394,E,1,3,2.88,102.907,M,47.093,M,,*5F",
        ]);
        assert_eq!(three[0].fix, FixMode::Fix2d);
        // No date yet anywhere: a position but no UTC.
        assert_eq!(three[0].utc, None);
        let rmc_only =
            merge(&["$GNRMC,055234.000,A,4739.71890,N,12219.58362,W,0.00,286.35,050826,,,A,V*13"]);
        assert_eq!(rmc_only[0].fix, FixMode::Fix2d);
    }

    #[test]
    fn date_carries_over_midnight() {
        let fixes = merge(&[
            &checksummed("GPRMC,235959.50,A,4134.498,N,09345.033,W,3.252,92.308,180320,,,A"),
            &checksummed("GPGGA,000000.50,4134.498,N,09345.033,W,1,09,1.0,278.020,M,-31.442,M,,"),
        ]);
        assert_eq!(fixes[0].utc.unwrap().date(), (2020, 3, 18));
        let next = fixes[1].utc.unwrap();
        assert_eq!(next.date(), (2020, 3, 19));
        assert_eq!(next.ms_of_day, 500);
    }

    #[test]
    fn timeout_emits_an_unfinished_epoch() {
        let mut m = EpochMerger::new(1000);
        let mut out = Vec::new();
        if let Sentence::Update(kind, u) = parse(GARMIN[0]) {
            m.push(kind, &u, 0, &mut |f| out.push(f));
        }
        m.poll(1000, &mut |f| out.push(f));
        assert!(out.is_empty());
        m.poll(1001, &mut |f| out.push(f));
        assert_eq!(out.len(), 1);
    }
}
