//! `wobble-size-budget ELF`: prints the firmware's flash, static SRAM and
//! CCM, and exits with 1 when flash exceeds its budget (384 KiB, the active
//! slot of the field-update layout) or CCM its 64 KiB, 2 on a usage error
//! or an unreadable file. Static SRAM is gated together with the stack
//! bound (`stack_bound.py --check`: at most 120 KiB), as the memory plan
//! in `firmware/docs/board.md` says.

use std::process::ExitCode;

use wobble_size_budget::{measure, CCM_BUDGET, FLASH_BUDGET};

fn kib(bytes: u64) -> f64 {
    bytes as f64 / 1024.0
}

fn main() -> ExitCode {
    let mut args = std::env::args_os().skip(1);
    let (Some(path), None) = (args.next(), args.next()) else {
        eprintln!("usage: wobble-size-budget FIRMWARE.elf");
        return ExitCode::from(2);
    };
    let shown = path.to_string_lossy().into_owned();
    let footprint = match std::fs::read(&path)
        .map_err(|e| e.to_string())
        .and_then(|data| measure(&data).map_err(|e| e.to_string()))
    {
        Ok(footprint) => footprint,
        Err(e) => {
            eprintln!("{shown}: {e}");
            return ExitCode::from(2);
        }
    };
    let mut within = true;
    println!(
        "static RAM: {} bytes ({:.1} KiB) of SRAM; with the stack bound at most 120 KiB \
         (stack_bound.py --check)",
        footprint.ram,
        kib(footprint.ram)
    );
    for (what, used, budget) in [
        ("flash", footprint.flash, FLASH_BUDGET),
        ("CCM", footprint.ccm, CCM_BUDGET),
    ] {
        let verdict = if used <= budget { "ok" } else { "OVER BUDGET" };
        println!(
            "{what}: {used} bytes ({:.1} KiB) of {:.0} KiB: {verdict}",
            kib(used),
            kib(budget)
        );
        within &= used <= budget;
    }
    if within {
        ExitCode::SUCCESS
    } else {
        eprintln!("{shown}: the firmware exceeds its size budget (firmware/docs/board.md)");
        ExitCode::from(1)
    }
}
