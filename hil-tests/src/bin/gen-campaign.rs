//! `gen-campaign`: writes a simulated kick-test campaign (one card log per
//! pass, and `truth.json` with the bicycle's wobble speed and every kick's
//! true eigenvalue) for `wobblog margin` and the docs' figures.
//!
//! ```text
//! cargo run -p wobble-hil --release --bin gen-campaign -- [--variant NAME] [--seed N] [--push] DIR
//! ```
//! Variants: `test-bicycle` (default), `light-rider`, `head-damping`,
//! `rack-load`. DIR must not exist yet (nothing is overwritten).

use std::path::PathBuf;
use std::process::ExitCode;

use wobble_hil::corpus::simulated::campaign::{self, Plan};

fn usage() -> &'static str {
    "usage: gen-campaign [--variant NAME] [--seed N] [--push] DIR"
}

fn main() -> ExitCode {
    let mut variant = "test-bicycle".to_owned();
    let mut seed = 1u64;
    let mut push = false;
    let mut dir = None;
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--variant" => variant = args.next().unwrap_or_default(),
            "--seed" => match args.next().and_then(|s| s.parse().ok()) {
                Some(s) => seed = s,
                None => {
                    eprintln!("gen-campaign: --seed takes a whole number\n{}", usage());
                    return ExitCode::from(2);
                }
            },
            "--push" => push = true,
            "-h" | "--help" => {
                println!("{}", usage());
                return ExitCode::SUCCESS;
            }
            a if a.starts_with('-') => {
                eprintln!("gen-campaign: unknown option {a}\n{}", usage());
                return ExitCode::from(2);
            }
            a => dir = Some(PathBuf::from(a)),
        }
    }
    let Some(dir) = dir else {
        eprintln!("gen-campaign: no output directory\n{}", usage());
        return ExitCode::from(2);
    };
    if dir.exists() {
        eprintln!(
            "gen-campaign: {} exists; give a new directory",
            dir.display()
        );
        return ExitCode::from(2);
    }
    let variants = match campaign::variants() {
        Ok(v) => v,
        Err(e) => {
            eprintln!("gen-campaign: {e}");
            return ExitCode::FAILURE;
        }
    };
    let Some(v) = variants.iter().find(|v| v.name == variant) else {
        let names: Vec<_> = variants.iter().map(|v| v.name).collect();
        eprintln!(
            "gen-campaign: no variant {variant}; one of {}",
            names.join(", ")
        );
        return ExitCode::from(2);
    };
    let plan = if push {
        Plan::default().with_push()
    } else {
        Plan::default()
    };
    let written = campaign::simulate(v, &plan, seed).and_then(|c| {
        let logs = c.write(&dir)?;
        Ok((c, logs))
    });
    match written {
        Ok((c, logs)) => {
            println!(
                "{}: {} logs, {} kicks, wobble speed {:.3} m/s",
                dir.display(),
                logs.len(),
                c.kicks.len(),
                c.wobble_speed_mps
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("gen-campaign: {e}");
            ExitCode::FAILURE
        }
    }
}
