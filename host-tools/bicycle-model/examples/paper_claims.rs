//! The seed paper's claims (`wobble_model::paper`) against a parameter file:
//! one line per claim with the verdict and the model's figures.
//!
//! `cargo run --release -p wobble-model --example paper_claims -- PARAMS [--markdown]`
//!
//! With `--markdown`, the rows of the claims table of
//! `host-tools/docs/model.md`.

use std::path::Path;
use std::process::ExitCode;

use wobble_model::paper::{Kind, Study, CLAIMS, LIGHT_RIDER_KG, TABLE_STEP_MPS};
use wobble_model::ParamSet;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (path, markdown) = match args.as_slice() {
        [path] => (path, false),
        [path, flag] if flag == "--markdown" => (path, true),
        _ => {
            eprintln!("usage: paper_claims PARAMS [--markdown]");
            return ExitCode::from(2);
        }
    };
    let set = match ParamSet::load(Path::new(path)) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("paper_claims: {e}");
            return ExitCode::FAILURE;
        }
    };
    let mut study = Study::new(&set, LIGHT_RIDER_KG, TABLE_STEP_MPS);
    let (mut agree, mut directions, mut agree_dir) = (0, 0, 0);
    for claim in CLAIMS {
        match claim.check(&mut study) {
            Ok(v) => {
                if markdown {
                    println!(
                        "| {} | §{} | {} | {} | {} | {} |",
                        claim.id,
                        claim.section,
                        claim.claim,
                        claim.test,
                        v.figures,
                        if v.agrees { "yes" } else { "no" }
                    );
                } else {
                    println!(
                        "{:<5} {:<4} {}",
                        claim.id,
                        if v.agrees { "yes" } else { "NO" },
                        v.figures
                    );
                }
                agree += usize::from(v.agrees);
                if claim.kind == Kind::Direction {
                    directions += 1;
                    agree_dir += usize::from(v.agrees);
                }
            }
            Err(e) => {
                eprintln!("paper_claims: {path}: claim {}: {e}", claim.id);
                return ExitCode::FAILURE;
            }
        }
    }
    println!(
        "{agree} of {} claims agree; directions: {agree_dir} of {directions}",
        CLAIMS.len()
    );
    ExitCode::SUCCESS
}
