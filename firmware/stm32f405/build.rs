//! Linker arguments: the workspace's `memory.x` (one file for the board
//! and the QEMU image), cortex-m-rt's `link.x` and defmt's `defmt.x`.
//!
//! And one image per build: the size-optimised release profile lives in
//! this crate's `.cargo/config.toml`, which cargo reads only when the
//! build starts in this directory. A release build started elsewhere (the
//! workspace root) would get the host tools' `opt-level = 3` and a
//! different, larger image than the one documented and measured; it is
//! refused with a message saying where to build from.

use std::path::PathBuf;

fn main() {
    let env = |name| std::env::var(name).unwrap_or_default();
    if env("PROFILE") == "release" && env("OPT_LEVEL") != "z" {
        eprintln!(
            "error: wobble-stm32f405 release builds take the size-optimised profile of \
             firmware/stm32f405/.cargo/config.toml, which cargo reads only from that \
             directory (this build has opt-level {}). Build the firmware with: \
             cd firmware/stm32f405 && cargo build --release",
            env("OPT_LEVEL")
        );
        std::process::exit(1);
    }
    let manifest = std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default();
    let root = PathBuf::from(manifest).join("../..");
    println!("cargo:rustc-link-search={}", root.display());
    println!("cargo:rerun-if-changed={}", root.join("memory.x").display());
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
    println!("cargo:rustc-link-arg-bins=--icf=all");
}
