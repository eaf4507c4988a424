//! The benchmark's 1000-speed sweep (0 to 9.99 m/s by 0.01), or its 1000
//! bare eigenvalue calls on its 1000 state matrices, repeated, for counting its instructions: the
//! difference between two repeat counts under `valgrind --tool=callgrind`
//! is the cost of the extra repeats, without loading and start-up
//! (`host-tools/docs/model.md`, *The eigenvalue solver*).
//!
//! `cargo build --release -p wobble-model --example sweep_cost`, then
//! `valgrind --tool=callgrind --callgrind-out-file=cg.out
//! target/release/examples/sweep_cost PARAMS sweep|eigenvalues REPEATS`

use std::hint::black_box;
use std::path::Path;
use std::process::ExitCode;

use wobble_model::{Model, ParamSet, Sweep};

fn run(path: &str, what: &str, repeats: &str) -> Result<(), String> {
    let set = ParamSet::load(Path::new(path)).map_err(|e| format!("{path}: {e}"))?;
    let model = Model::from_set(&set).map_err(|e| format!("{path}: {e}"))?;
    let repeats: usize = repeats
        .parse()
        .map_err(|_| format!("not a repeat count: {repeats}"))?;
    let speeds: Vec<f64> = (0..1000).map(|i| f64::from(i) * 0.01).collect();
    // The bare calls' matrices are built once, outside the repeats.
    let matrices: Vec<_> = speeds.iter().map(|&u| model.state_matrix(u)).collect();
    for _ in 0..repeats {
        match what {
            "sweep" => {
                let sweep = Sweep::run(&model, black_box(&speeds), |_| {})
                    .map_err(|e| format!("{path}: {e}"))?;
                black_box(sweep);
            }
            "eigenvalues" => {
                for a in black_box(&matrices) {
                    black_box(wobble_model::eig::eigenvalues(a));
                }
            }
            _ => return Err(format!("not sweep or eigenvalues: {what}")),
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [path, what, repeats] = args.as_slice() else {
        eprintln!("usage: sweep_cost PARAMS sweep|eigenvalues REPEATS");
        return ExitCode::FAILURE;
    };
    match run(path, what, repeats) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("sweep_cost: {e}");
            ExitCode::FAILURE
        }
    }
}
