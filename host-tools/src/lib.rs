//! Library behind the `wobblog` CLI: reading card logs into rows, exports and
//! analyses, reusing the firmware's core crate for everything the logger does.
#![warn(missing_docs)]

pub mod analysis;
pub mod cli;
pub mod cmd;
pub mod codes;
pub mod csv_input;
pub mod dataset;
pub mod error;
pub mod events;
pub mod export;
pub mod inputs;
pub mod interrupt;
pub mod losses;
pub mod output;
pub mod owner;
pub mod plot;
pub mod reader;
pub mod report;
pub mod resample;
pub mod rows;
pub mod spool;
pub mod summary;
pub mod text;
pub mod time;
pub mod words;

pub use error::CliError;
