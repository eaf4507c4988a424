//! One build, one image: the firmware build script's rule
//! (`firmware/stm32f405/build/one_image.rs`). A release build gets the
//! crate's size profile only from its own directory; the environment's
//! release-profile overrides are refused too.

#[path = "../../firmware/stm32f405/build/one_image.rs"]
mod one_image;

use one_image::{refusal, SIZE_PROFILE_VALUE};

const SIZE: &str = SIZE_PROFILE_VALUE;

#[test]
fn a_release_build_from_the_crate_directory_passes() {
    assert_eq!(refusal("release", "z", SIZE, ["PATH", "HOME"]), None);
    assert_eq!(
        refusal("debug", "0", "", ["CARGO_PROFILE_RELEASE_LTO"]),
        None
    );
}

#[test]
fn a_release_build_without_the_crate_profile_is_refused() {
    let why = refusal("release", "3", "", ["PATH"]).expect("refused");
    assert!(
        why.contains("cd firmware/stm32f405 && cargo build --release"),
        "{why}"
    );
}

/// `CARGO_PROFILE_RELEASE_OPT_LEVEL=z` at the workspace root gives the
/// opt-level the old check looked at, with the root's LTO and codegen
/// units: the crate's `.cargo/config.toml` was not read, and it is refused.
#[test]
fn an_opt_level_from_the_environment_at_the_root_is_refused() {
    let why = refusal("release", "z", "", ["CARGO_PROFILE_RELEASE_OPT_LEVEL"]).expect("refused");
    assert!(
        why.contains("cd firmware/stm32f405 && cargo build --release"),
        "{why}"
    );
}

/// In the crate directory, an override in the environment would change the
/// image as well (cargo takes the environment over the config file).
#[test]
fn profile_overrides_in_the_crate_directory_are_refused() {
    for name in [
        "CARGO_PROFILE_RELEASE_OPT_LEVEL",
        "CARGO_PROFILE_RELEASE_LTO",
    ] {
        let why = refusal("release", "z", SIZE, ["PATH", name]).expect("refused");
        assert!(why.contains(name), "{why}");
    }
    let why = refusal("release", "s", SIZE, ["PATH"]).expect("refused");
    assert!(why.contains("opt-level s"), "{why}");
}

/// The crate's `.cargo/config.toml` sets the variable the rule reads, and
/// the build script reruns on every profile override it could be given.
#[test]
fn the_crate_config_proves_it_was_read() {
    let config = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../firmware/stm32f405/.cargo/config.toml"
    ))
    .expect("the crate's cargo config");
    let line = format!(
        "{} = \"{}\"",
        one_image::SIZE_PROFILE_VAR,
        one_image::SIZE_PROFILE_VALUE
    );
    assert!(config.lines().any(|l| l.trim() == line), "{line} missing");
    assert!(one_image::PROFILE_SETTINGS.contains(&"OPT_LEVEL"));
    assert!(one_image::PROFILE_OVERRIDE_PREFIX.ends_with('_'));
}
