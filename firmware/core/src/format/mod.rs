//! The on-card log format, version 1: 512-byte CRC-protected blocks of
//! records. The byte layout is specified in `firmware/FORMAT.md`.

pub mod block;
pub mod codec;
mod crc_window;
pub mod decoder;
pub mod encoder;
pub mod header;
pub mod limits;
pub mod recent;
pub mod record;
mod varint;

pub use block::{Block, BlockError, BlockHeader, BLOCK_LEN};
pub use codec::{EncodeError, RecordError, Records};
pub use decoder::{DecodeStats, Decoder, Event, Gap, OutOfRange, Outcome, SkipCause};
pub use encoder::BlockEncoder;
pub use record::*;
