//! One module per `wobblog` subcommand: its clap arguments and its `run`.

pub mod completions;
pub mod config;
pub mod decode;
pub mod detect;
pub mod encode;
pub mod events;
pub mod export;
pub mod gpx;
pub mod info;
pub mod logs;
pub mod margin;
pub mod margin_model;
pub mod margin_weave;
pub mod model;
pub mod nmea;
pub mod plot;
pub mod report;
pub mod selftest;
pub mod summary;
pub mod wobble;
