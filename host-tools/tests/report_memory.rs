//! The ride view draws a run's frames in memory that does not grow with
//! the run: the heap its drawing pass (thinned signals, roll estimate,
//! spectrogram, GPS track) holds at its peak is the same for a run five
//! times longer, and the drawings are the same size. Counted by an
//! allocator that keeps the live and peak bytes of this test binary (one
//! test, so nothing else allocates meanwhile).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

use wobble_core::format::{FixMode, FrameStatus};
use wobblog::analysis::Ride;
use wobblog::report::ride::{Drawing, Drawn};
use wobblog::report::series::OVERVIEW_ROWS;
use wobblog::rows::{GpsColumns, Row};
use wobblog::summary::Summary;

/// The system allocator, counting.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grew(bytes: usize) {
    let live = LIVE.fetch_add(bytes, Relaxed) + bytes;
    PEAK.fetch_max(live, Relaxed);
}

// SAFETY: every call is passed to the system allocator unchanged; only
// the counters are added.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: as the caller promised for `layout`.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        // SAFETY: `p` came from `alloc` or `realloc` with `layout`.
        unsafe { System.dealloc(p, layout) };
        LIVE.fetch_sub(layout.size(), Relaxed);
    }

    unsafe fn realloc(&self, p: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: as the caller promised for `p`, `layout` and `new_size`.
        let q = unsafe { System.realloc(p, layout, new_size) };
        if !q.is_null() {
            if new_size >= layout.size() {
                grew(new_size - layout.size());
            } else {
                LIVE.fetch_sub(layout.size() - new_size, Relaxed);
            }
        }
        q
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

const FS_HZ: f64 = 100.0;

/// Frame `i` of the run: a 6.4 Hz steering sine, a weave in the roll
/// rate, speed rising, a GPS fix every fifth frame moving north.
fn row(i: usize) -> Row {
    let t = i as f64 / FS_HZ;
    let fix = i / 5;
    Row {
        t_s: t,
        accel_g: [0.01 * (0.3 * t).sin(), 0.02 * (0.7 * t).sin(), 1.0],
        gyro_dps: [5.0 * (4.0 * t).sin(), 0.5, 2.0 * (0.1 * t).sin()],
        steer_deg: (std::f64::consts::TAU * 6.4 * t).sin() + 0.2 * (0.05 * t).sin(),
        speed_mps: 4.0 + (0.01 * t).sin(),
        wheel_count: 0,
        status: FrameStatus::default(),
        gps: Some(GpsColumns {
            lat_deg: 52.0 + fix as f64 * 1e-6,
            lon_deg: 6.0,
            speed_mps: None,
            fix: FixMode::Fix3d,
        }),
        utc_us: None,
        derived: Default::default(),
        run: None,
    }
}

/// The run of `frames` frames as the first pass leaves it: its summary
/// (frames, span, rate, an alert and two markers), no episode.
fn ride(frames: usize) -> Ride {
    let end = (frames - 1) as f64 / FS_HZ;
    let mut summary = Summary {
        sample_rate_hz: Some(FS_HZ as u16),
        samples: frames as u64,
        frame_range_s: Some((0.0, end)),
        markers: vec![100.0, 0.5 * end],
        ..Summary::default()
    };
    summary.alerts.push(wobblog::summary::AlertSpan {
        on_s: 300.0,
        off_s: Some(303.0),
        freq_hz: 6.4,
        amp_deg: 1.0,
    });
    Ride {
        path: "RUN00001.WBL".into(),
        summary,
        episodes: Vec::new(),
        distance_m: 0.0,
        max_speed_mps: 0.0,
        host_kicks: None,
        weave_kicks: Vec::new(),
    }
}

/// The drawing of a run of `frames` frames, and the most heap it held
/// beyond what was live before it.
fn drawn(frames: usize) -> (Drawn, usize) {
    let ride = ride(frames);
    let before = LIVE.load(Relaxed);
    PEAK.store(before, Relaxed);
    let mut drawing = Drawing::new(&ride);
    for i in 0..frames {
        drawing.push(&row(i));
    }
    let drawn = drawing.finish();
    (drawn, PEAK.load(Relaxed) - before)
}

#[test]
fn the_drawing_of_a_run_holds_no_more_for_a_longer_run() {
    // 17 min and 83 min at 100 Hz, both past every limit of the drawing
    // (16 000 rows, 1200 spectra, 4000 track points). Holding the run
    // would cost at least 8 bytes a frame per channel: 3.2 MB more for
    // the longer one.
    let (short, short_peak) = drawn(100_000);
    let (long, long_peak) = drawn(500_000);
    eprintln!("peak heap: {short_peak} B for 100 000 frames, {long_peak} B for 500 000");
    assert!(
        long_peak < short_peak + 1_000_000,
        "{long_peak} B against {short_peak} B"
    );
    assert!(long_peak < 16_000_000, "{long_peak} B");
    // The drawings are sized by the display, not by the run.
    for d in [&short, &long] {
        assert!(
            d.series.t.len() <= OVERVIEW_ROWS + 1_600,
            "{}",
            d.series.t.len()
        );
        assert!(d.series.t.len() > OVERVIEW_ROWS / 2, "{}", d.series.t.len());
    }
    let (s, l) = (
        short.spectrogram.as_ref().unwrap(),
        long.spectrogram.as_ref().unwrap(),
    );
    assert_eq!(s.size, l.size);
    let (s_track, l_track) = (short.track_svg.unwrap(), long.track_svg.unwrap());
    let points = |svg: &str| svg.matches(',').count();
    assert!(points(&l_track) <= 4_100 && points(&s_track) <= 4_100);
    assert!(
        (long.min_speed_mps - 3.0).abs() < 1e-3,
        "{}",
        long.min_speed_mps
    );
}
