//! The bicycles BicycleParameters measured (Moore 2012), whose
//! `*Benchmark.txt` files this crate's tests carry
//! (`tests/data/bicycleparameters/`): the family every check that reaches
//! beyond our own bicycle runs over, named once.

use std::path::PathBuf;

/// The benchmark and the measured bicycles whose weave and capsize speeds
/// BicycleParameters published beside them (`critical_speeds.csv`), each by
/// the name of its `NAMEBenchmark.txt`. (`SilverBenchmark.txt`, kept as
/// BicycleParameters ships it to test the lines the Whipple model leaves
/// out, has none.)
pub const MEASURED_BICYCLES: [&str; 7] = [
    "Benchmark",
    "Browser",
    "Crescendo",
    "Fisher",
    "Pista",
    "Stratos",
    "Yellow",
];

/// The `*Benchmark.txt` of `name` in this crate's source tree.
#[must_use]
pub fn measured_bicycle_file(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/bicycleparameters")
        .join(format!("{name}Benchmark.txt"))
}
