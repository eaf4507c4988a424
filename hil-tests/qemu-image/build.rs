//! Linker arguments only: the workspace's `memory.x` (shared with the board)
//! and cortex-m-rt's `link.x`.

use std::path::PathBuf;

fn main() {
    let root =
        PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default()).join("../..");
    println!("cargo:rustc-link-search={}", root.display());
    println!("cargo:rerun-if-changed={}", root.join("memory.x").display());
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
}
