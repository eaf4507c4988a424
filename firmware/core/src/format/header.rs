//! The records that open every log and make it self-describing.

use super::record::{
    ChannelDef, ConfigLine, LogInfo, Record, ACCEL_COUNTS_PER_G, GYRO_COUNTS_PER_DPS,
    STEER_COUNTS_PER_DEG,
};

/// One channel of the frame record: name, unit, counts per unit.
pub type ChannelSpec = (&'static str, &'static str, f32);

/// The frame's channels in record order, as written into every header.
pub const FRAME_CHANNELS: [ChannelSpec; 11] = [
    ("ax", "g", ACCEL_COUNTS_PER_G),
    ("ay", "g", ACCEL_COUNTS_PER_G),
    ("az", "g", ACCEL_COUNTS_PER_G),
    ("gx", "dps", GYRO_COUNTS_PER_DPS),
    ("gy", "dps", GYRO_COUNTS_PER_DPS),
    ("gz", "dps", GYRO_COUNTS_PER_DPS),
    ("steer", "deg", STEER_COUNTS_PER_DEG),
    ("wheel_count", "pulses", 1.0),
    ("wheel_edge_age", "us", 1.0),
    ("speed", "mps", 1000.0),
    ("status", "bits", 1.0),
];

/// The header records of a log, in the order they are written: the log
/// info, one channel definition per frame channel, then each config line.
pub fn header_records<'a>(
    info: LogInfo<'a>,
    config: impl IntoIterator<Item = &'a str> + 'a,
) -> impl Iterator<Item = Record<'a>> + 'a {
    let t_us = info.t_us;
    let channels =
        FRAME_CHANNELS
            .iter()
            .zip(0u8..)
            .map(move |(&(name, unit, counts_per_unit), index)| {
                Record::Channel(ChannelDef {
                    t_us,
                    index,
                    name,
                    unit,
                    counts_per_unit,
                })
            });
    core::iter::once(Record::LogInfo(info))
        .chain(channels)
        .chain(
            config
                .into_iter()
                .map(move |text| Record::Config(ConfigLine { t_us, text })),
        )
}
