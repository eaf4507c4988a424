//! One module per `wobblog` subcommand: its clap arguments and its `run`.

pub mod decode;
pub mod encode;
pub mod info;
pub mod nmea;
