//! Linker arguments only: the workspace's `memory.x`, cortex-m-rt's
//! `link.x`, defmt's `defmt.x` and embedded-test's `embedded-test.x` (the
//! test table probe-rs reads), for the test binaries.

use std::path::PathBuf;

fn main() {
    let manifest = std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default();
    let root = PathBuf::from(manifest).join("../..");
    println!("cargo:rustc-link-search={}", root.display());
    println!("cargo:rerun-if-changed={}", root.join("memory.x").display());
    // embedded-test's macro tests `cfg(rust_analyzer)`.
    println!("cargo:rustc-check-cfg=cfg(rust_analyzer)");
    for script in ["link.x", "defmt.x", "embedded-test.x"] {
        println!("cargo:rustc-link-arg-tests=-T{script}");
    }
}
