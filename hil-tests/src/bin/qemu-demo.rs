//! Runs the firmware under QEMU on the bundled Figure-6 ride and leaves the
//! card image and its log in a folder (`hil-tests/demo.sh` calls this, then
//! decodes the log with `wobblog`).
//!
//! Usage: `qemu-demo OUT_DIR`

use std::path::PathBuf;
use std::process::ExitCode;

use wobble_hil::qemu::{self, card, Scenario};

/// 30 s: the whole Figure-6 ride.
const FRAMES: u32 = 3000;

fn main() -> ExitCode {
    let Some(out) = std::env::args_os().nth(1).map(PathBuf::from) else {
        eprintln!("usage: qemu-demo OUT_DIR");
        return ExitCode::from(2);
    };
    match run(&out) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("qemu-demo: {e}");
            ExitCode::from(1)
        }
    }
}

fn run(out: &std::path::Path) -> Result<(), String> {
    let bundle = qemu::bundle(FRAMES)?;
    println!("ride: {}", bundle.ride.truth.description);
    println!(
        "GPS: {} ({} NMEA chunks)",
        qemu::GPS_CAPTURE,
        bundle.gps.len()
    );
    println!("running the firmware under QEMU (netduinoplus2, 30 s of virtual time)...");
    let setup = bundle.setup(out.to_path_buf(), Scenario::ride(FRAMES));
    let outcome = qemu::run(&setup, |_| Ok(()), show)?;
    if outcome.code != 0 {
        return Err(format!("the firmware exited with code {}", outcome.code));
    }
    let virtual_s = f64::from(FRAMES) / 100.0;
    println!(
        "done: {virtual_s:.0} s of ride in {:.1} s ({:.0}x real time)",
        outcome.wall.as_secs_f64(),
        virtual_s / outcome.wall.as_secs_f64()
    );
    for (name, data) in card::root_files(&outcome.card)? {
        let path = out.join(&name);
        std::fs::write(&path, data).map_err(|e| format!("{}: {e}", path.display()))?;
        println!("card file {name} -> {}", path.display());
    }
    let fsck = card::fsck(&outcome.card)?;
    println!(
        "fsck.fat -n: {}",
        if fsck.code == 0 {
            "clean"
        } else {
            "PROBLEMS (see below)"
        }
    );
    if fsck.code != 0 {
        println!("{}", fsck.text);
    }
    Ok(())
}

/// The firmware's report lines, for a person watching.
fn show(line: &str) {
    let f = |key: &str| {
        line.split(' ')
            .find_map(|kv| kv.strip_prefix(key)?.strip_prefix('='))
            .unwrap_or("?")
    };
    let t_s = f("t_us").parse::<f64>().map_or(0.0, |us| us / 1e6);
    if line.starts_with("ALERT on") {
        println!(
            "  {t_s:6.2} s  *** WOBBLE ALERT: {} Hz, {} deg ***",
            f("freq_hz"),
            f("amp_deg")
        );
    } else if line.starts_with("ALERT off") {
        println!("  {t_s:6.2} s  alert off");
    } else {
        println!("  {line}");
    }
}
