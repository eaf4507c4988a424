//! Offline analysis of a whole run: roll angle from the IMU, and wobble
//! episodes measured as the seed paper does (frequency, growth rate, speed).

pub mod campaign_kicks;
pub mod censor;
pub mod episodes;
pub mod filter;
pub mod kick_episodes;
pub mod kicks;
pub mod margin;
pub mod ride;
pub mod roll;
pub mod run;
pub mod search;
pub mod sinefit;
pub mod weave;

pub use censor::Cut;
pub use episodes::{find_episodes, wobble_speed_mps, Episode, Measured, Stability};
pub use kicks::{find_kicks, find_mode_kicks, Kick, KickMode};
pub use ride::Ride;
pub use roll::estimate_roll_deg;
pub use run::Run;
