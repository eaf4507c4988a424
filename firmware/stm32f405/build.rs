//! Linker arguments: the workspace's `memory.x` (one file for the board
//! and the QEMU image), cortex-m-rt's `link.x` and defmt's `defmt.x`.
//!
//! And one image per build: a release build that would not get the
//! crate's size-optimised profile is refused with a message saying where
//! to build from (`build/one_image.rs`).

use std::path::PathBuf;

#[path = "build/one_image.rs"]
mod one_image;

fn main() {
    let env = |name| std::env::var(name).unwrap_or_default();
    println!("cargo:rerun-if-env-changed={}", one_image::SIZE_PROFILE_VAR);
    for setting in one_image::PROFILE_SETTINGS {
        println!(
            "cargo:rerun-if-env-changed={}{setting}",
            one_image::PROFILE_OVERRIDE_PREFIX
        );
    }
    let names: Vec<String> = std::env::vars_os()
        .filter_map(|(name, _)| name.into_string().ok())
        .collect();
    if let Some(why) = one_image::refusal(
        &env("PROFILE"),
        &env("OPT_LEVEL"),
        &env(one_image::SIZE_PROFILE_VAR),
        names.iter().map(String::as_str),
    ) {
        eprintln!("error: {why}");
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
