//! One build, one image: the rule the build script applies, in a file of
//! its own so that the host tests (`hil-tests/tests/one_image.rs`) check it.
//!
//! The firmware's size-optimised release profile lives in
//! `firmware/stm32f405/.cargo/config.toml`, which cargo reads only when the
//! build starts in that directory; that file also sets
//! [`SIZE_PROFILE_VAR`] for the build script, the proof that it was read.
//! A release build is refused when the file was not read (started at the
//! workspace root, say), when the environment overrides any release
//! profile setting (`CARGO_PROFILE_RELEASE_OPT_LEVEL=z` at the root used to
//! slip past a check of the opt-level alone, with the root's LTO and
//! codegen units: another image), or when the opt-level is not `z`.

/// Set to [`SIZE_PROFILE_VALUE`] by the crate's `.cargo/config.toml`.
pub const SIZE_PROFILE_VAR: &str = "WOBBLE_FIRMWARE_SIZE_PROFILE";
/// The value that proves the crate's `.cargo/config.toml` was read.
pub const SIZE_PROFILE_VALUE: &str = "firmware/stm32f405";
/// Environment variables of this prefix override the release profile.
pub const PROFILE_OVERRIDE_PREFIX: &str = "CARGO_PROFILE_RELEASE_";
/// The release profile settings cargo takes from the environment (the
/// build script reruns when one changes).
pub const PROFILE_SETTINGS: [&str; 11] = [
    "OPT_LEVEL",
    "LTO",
    "CODEGEN_UNITS",
    "DEBUG",
    "DEBUG_ASSERTIONS",
    "OVERFLOW_CHECKS",
    "PANIC",
    "INCREMENTAL",
    "STRIP",
    "SPLIT_DEBUGINFO",
    "RPATH",
];

/// Why this build would not give the documented image, or `None` when it
/// does: `profile` and `opt_level` as cargo gives them to build scripts
/// (`PROFILE`, `OPT_LEVEL`), `size_profile` the value of
/// [`SIZE_PROFILE_VAR`] (empty when unset), `env_names` the names of the
/// environment's variables.
pub fn refusal<'a>(
    profile: &str,
    opt_level: &str,
    size_profile: &str,
    env_names: impl IntoIterator<Item = &'a str>,
) -> Option<String> {
    if profile != "release" {
        return None;
    }
    const HOW: &str = "Build the firmware with: cd firmware/stm32f405 && cargo build --release";
    if size_profile != SIZE_PROFILE_VALUE {
        return Some(format!(
            "wobble-stm32f405 release builds take the size-optimised profile of \
             firmware/stm32f405/.cargo/config.toml, which cargo reads only from that \
             directory (this build has opt-level {opt_level}). {HOW}"
        ));
    }
    let overrides: Vec<&str> = env_names
        .into_iter()
        .filter(|name| name.starts_with(PROFILE_OVERRIDE_PREFIX))
        .collect();
    if !overrides.is_empty() {
        return Some(format!(
            "{} in the environment overrides the firmware's release profile \
             (firmware/stm32f405/.cargo/config.toml): unset it. {HOW}",
            overrides.join(", ")
        ));
    }
    if opt_level != "z" {
        return Some(format!(
            "wobble-stm32f405 release builds are optimised for size (opt-level z), \
             this one has opt-level {opt_level}. {HOW}"
        ));
    }
    None
}
