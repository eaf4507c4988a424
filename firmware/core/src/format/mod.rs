//! The on-card log format, version 1: 512-byte CRC-protected blocks of
//! records. The byte layout is specified in `firmware/FORMAT.md`.

pub mod record;

pub use record::*;
