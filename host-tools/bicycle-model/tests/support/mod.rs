//! What the integration tests share.

use std::path::Path;

use wobble_model::ParamSet;

/// The parameter file `name` of the crate's `params/`.
pub fn bundled(name: &str) -> ParamSet {
    ParamSet::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("params")
            .join(name),
    )
    .unwrap()
}
