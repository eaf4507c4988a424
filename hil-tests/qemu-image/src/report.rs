//! Lines for the test harness on semihosting stdout, one event per line,
//! `KEY key=value ...`. Each line is formatted first and written in one
//! call, so lines from the two executors never interleave.

use core::fmt::Write as _;

use wobble_core::detector::AlertEvent;

/// Writes one line.
pub fn line(args: core::fmt::Arguments<'_>) {
    let mut text = heapless::String::<256>::new();
    let _ = text.write_fmt(args);
    let _ = text.push('\n');
    semihosting::print!("{text}");
}

/// An alert switching, as it happens.
pub fn alert(t_us: u64, ev: AlertEvent) {
    match ev {
        AlertEvent::On { freq_hz, amp_deg } => line(format_args!(
            "ALERT on t_us={t_us} freq_hz={freq_hz:.2} amp_deg={amp_deg:.2}"
        )),
        AlertEvent::Off => line(format_args!("ALERT off t_us={t_us}")),
    }
}

/// A stall injected into a block write.
pub fn stall(write: u32, ms: u32) {
    line(format_args!(
        "STALL write={write} ms={ms} t_us={}",
        embassy_time::Instant::now().as_micros()
    ));
}

/// The power goes during block write `write` (`torn` of its bytes
/// programmed; 0 also for a cut before it): nothing more is written; QEMU
/// exits with code 3.
pub fn power_cut(write: u32, torn: usize) -> ! {
    line(format_args!(
        "CUT write={write} torn={torn} frames={} t_us={}",
        crate::FRAMES_SAMPLED.load(core::sync::atomic::Ordering::Relaxed),
        embassy_time::Instant::now().as_micros()
    ));
    semihosting::process::exit(3)
}
