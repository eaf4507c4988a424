//! `gen-corpus`: writes (or checks) the detector corpus: the signal-model
//! family and, in `simulated/`, the rides simulated from the bicycle model.
//!
//! ```text
//! cargo run -p wobble-hil --release --bin gen-corpus            # committed fixtures + manifest
//! cargo run -p wobble-hil --release --bin gen-corpus -- --all   # also the long rides, into generated/
//! cargo run -p wobble-hil --release --bin gen-corpus -- --check # exit 1 if the files differ
//! ```
//! An optional last argument names the output directory (default
//! `hil-tests/fixtures/corpus`).

use std::path::PathBuf;
use std::process::ExitCode;

use wobble_hil::corpus;

fn main() -> ExitCode {
    let mut all = false;
    let mut check = false;
    let mut dir = corpus::corpus_dir();
    for arg in std::env::args().skip(1) {
        match arg.as_str() {
            "--all" => all = true,
            "--check" => check = true,
            "-h" | "--help" => {
                println!("usage: gen-corpus [--all] [--check] [DIR]");
                return ExitCode::SUCCESS;
            }
            a if a.starts_with('-') => {
                eprintln!("gen-corpus: unknown option {a}");
                return ExitCode::from(2);
            }
            a => dir = PathBuf::from(a),
        }
    }
    let fixtures = corpus::generate();
    let simulated = match corpus::simulated::generate() {
        Ok(f) => f,
        Err(e) => {
            eprintln!("gen-corpus: simulated family: {e}");
            return ExitCode::FAILURE;
        }
    };
    let sim_dir = dir.join("simulated");
    let mut files = vec![
        (dir.join("manifest.json"), corpus::manifest_json(&fixtures)),
        (
            sim_dir.join("manifest.json"),
            corpus::simulated::manifest_json(&simulated),
        ),
    ];
    for (family, dir) in [(&fixtures, &dir), (&simulated, &sim_dir)] {
        for f in family.iter().filter(|f| f.truth.committed || all) {
            files.push((corpus::fixture_path(dir, &f.truth), f.csv.clone()));
        }
    }
    let mut bad = 0;
    for (path, text) in files {
        if check {
            match std::fs::read_to_string(&path) {
                Ok(on_disk) if on_disk == text => {}
                Ok(_) => {
                    eprintln!(
                        "gen-corpus: {} differs from the generator's output",
                        path.display()
                    );
                    bad += 1;
                }
                Err(e) => {
                    eprintln!("gen-corpus: {}: {e}", path.display());
                    bad += 1;
                }
            }
            continue;
        }
        let written = path
            .parent()
            .map_or(Ok(()), std::fs::create_dir_all)
            .and_then(|()| std::fs::write(&path, text));
        if let Err(e) = written {
            eprintln!("gen-corpus: {}: {e}", path.display());
            return ExitCode::FAILURE;
        }
        println!("wrote {}", path.display());
    }
    if bad > 0 {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}
