//! TDK InvenSense ICM-42688-P 6-axis IMU on SPI (`embedded-hal-async`).
//!
//! Configured for the wobble logger: ±16 g and ±500 deg/s by default (the
//! study needs at least ±10 g and ±300 deg/s), both sensors in low-noise mode
//! at a 100 Hz output data rate, read by the 100 Hz sampler.
//!
//! **Anti-aliasing.** The chip samples far faster than 100 Hz and decimates;
//! two of its filters decide what aliases into the 100 Hz output:
//! - the analogue-rate anti-alias filter (AAF, 2nd order) is set to its
//!   lowest corner, 42 Hz (datasheet table: DELT 1, DELTSQR 1, BITSHIFT 15);
//! - the UI filter ahead of the final decimation runs at max(400 Hz, ODR) =
//!   400 Hz; it is set to 3rd order with a bandwidth of 400 Hz / 10 = 40 Hz.
//!
//! Together that is a 5th-order roll-off from about 40 Hz. Modelled as
//! Butterworth sections, a component at 60 Hz (which would fold onto 40 Hz)
//! is down by about 18 dB, one at 90 Hz (folding onto 10 Hz, next to the
//! wobble band) by about 35 dB. The wobble band, 6-9 Hz, is flat to within
//! a fraction of a dB and delayed by about 15 ms.
//!
//! **Health.** [`Icm42688::init`] checks `WHO_AM_I`: a bus with nothing on it
//! reads 0x00 or 0xFF ([`Error::NoResponse`]), another part reads something
//! else ([`Error::WrongId`]). [`Icm42688::read`] reports a sensor whose
//! registers hold the "no data" marker ([`Error::NotReady`]: it reset or
//! powered down), and one that went away after `init` ([`Error::NoResponse`]:
//! the burst reads all 0xFF or all 0x00, the floating bus; a live sensor
//! always has gravity on some axis). A sensor that answers with frozen values is found one level
//! up, by [`crate::imu::Imu`]. Each error maps to the sampler's
//! [`SensorError`] ([`Error::sensor_error`]), which records it as an IMU
//! fault; the caller re-runs `init` to recover.

use embedded_hal_async::delay::DelayNs;
use embedded_hal_async::spi::{Operation, SpiDevice};

use crate::app::ports::SensorError;
use crate::imu::{ImuConfig, RawImu};

/// Register addresses and fields (datasheet DS-000347, section 14).
pub mod reg {
    /// Bank-select register, present in every bank.
    pub const REG_BANK_SEL: u8 = 0x76;

    // User bank 0.
    /// Bank 0: soft reset.
    pub const DEVICE_CONFIG: u8 = 0x11;
    /// Bank 0: first data register: ACCEL_DATA_X1 .. GYRO_DATA_Z0 follow,
    /// 12 bytes, big-endian.
    pub const ACCEL_DATA_X1: u8 = 0x1F;
    /// Bank 0: power modes of gyro and accelerometer.
    pub const PWR_MGMT0: u8 = 0x4E;
    /// Bank 0: gyro full scale and output data rate.
    pub const GYRO_CONFIG0: u8 = 0x4F;
    /// Bank 0: accelerometer full scale and output data rate.
    pub const ACCEL_CONFIG0: u8 = 0x50;
    /// Bank 0: gyro UI filter order (bits 3:2).
    pub const GYRO_CONFIG1: u8 = 0x51;
    /// Bank 0: UI filter bandwidths, accel (7:4) and gyro (3:0).
    pub const GYRO_ACCEL_CONFIG0: u8 = 0x52;
    /// Bank 0: accelerometer UI filter order (bits 4:3).
    pub const ACCEL_CONFIG1: u8 = 0x53;
    /// Bank 0: device identity.
    pub const WHO_AM_I: u8 = 0x75;
    /// Bank 0: INT1/INT2 pin configuration (register map, INT_CONFIG): bit 2
    /// INT1_MODE (0 pulsed), bit 1 INT1_DRIVE_CIRCUIT (1 push-pull), bit 0
    /// INT1_POLARITY (1 active high).
    pub const INT_CONFIG: u8 = 0x14;
    /// Bank 0: FIFO mode, bits 7:6 (FIFO_MODE): 01 stream-to-FIFO.
    pub const FIFO_CONFIG: u8 = 0x16;
    /// Bank 0: FIFO byte count, high byte first (INTF_CONFIG0 at
    /// reset: FIFO_COUNT_REC 0, a count of bytes; FIFO_COUNT_ENDIAN 1,
    /// big-endian); reading the high byte
    /// latches the low one.
    pub const FIFO_COUNTH: u8 = 0x2E;
    /// Bank 0: the FIFO's read port (FIFO_DATA): a burst read of it
    /// pops bytes, the address does not advance.
    pub const FIFO_DATA: u8 = 0x30;
    /// Bank 0: FIFO contents (FIFO_CONFIG1): bit 2 FIFO_TEMP_EN, bit 1
    /// FIFO_GYRO_EN, bit 0 FIFO_ACCEL_EN; with both sensors on, each
    /// sample is one 16-byte packet 3 (section 6, FIFO packet structure).
    pub const FIFO_CONFIG1: u8 = 0x5F;
    /// Bank 0: bit 4 INT_ASYNC_RESET, 1 at reset; the register
    /// description asks for 0 "for proper INT1 and INT2 pin operation".
    pub const INT_CONFIG1: u8 = 0x64;
    /// Bank 0: what drives INT1 (INT_SOURCE0): bit 3 UI_DRDY_INT1_EN.
    pub const INT_SOURCE0: u8 = 0x65;
    /// Bank 0: SIGNAL_PATH_RESET, bit 1 FIFO_FLUSH (self-clearing).
    pub const SIGNAL_PATH_RESET: u8 = 0x4B;

    // User bank 1: gyro anti-alias filter.
    /// Bank 1: GYRO_AAF_DELT (5:0).
    pub const GYRO_CONFIG_STATIC3: u8 = 0x0C;
    /// Bank 1: GYRO_AAF_DELTSQR bits 7:0.
    pub const GYRO_CONFIG_STATIC4: u8 = 0x0D;
    /// Bank 1: GYRO_AAF_BITSHIFT (7:4), GYRO_AAF_DELTSQR bits 11:8 (3:0).
    pub const GYRO_CONFIG_STATIC5: u8 = 0x0E;

    // User bank 2: accelerometer anti-alias filter.
    /// Bank 2: ACCEL_AAF_DELT (6:1), ACCEL_AAF_DIS (0).
    pub const ACCEL_CONFIG_STATIC2: u8 = 0x03;
    /// Bank 2: ACCEL_AAF_DELTSQR bits 7:0.
    pub const ACCEL_CONFIG_STATIC3: u8 = 0x04;
    /// Bank 2: ACCEL_AAF_BITSHIFT (7:4), ACCEL_AAF_DELTSQR bits 11:8 (3:0).
    pub const ACCEL_CONFIG_STATIC4: u8 = 0x05;

    /// Set in the address byte of a read.
    pub const READ: u8 = 0x80;
    /// `WHO_AM_I` of the ICM-42688-P.
    pub const WHO_AM_I_VALUE: u8 = 0x47;
    /// `DEVICE_CONFIG`: SOFT_RESET_CONFIG.
    pub const SOFT_RESET: u8 = 0x01;
    /// `PWR_MGMT0`: gyro (3:2) and accel (1:0) in low-noise mode.
    pub const PWR_GYRO_ACCEL_LOW_NOISE: u8 = 0b0000_1111;
    /// Output data rate code for 100 Hz (GYRO_ODR / ACCEL_ODR, bits 3:0).
    pub const ODR_100HZ: u8 = 0b1000;
    /// Shift of the full-scale field (bits 7:5) in GYRO/ACCEL_CONFIG0.
    pub const FS_SEL_SHIFT: u8 = 5;
    /// GYRO_UI_FILT_ORD field (bits 3:2) of GYRO_CONFIG1.
    pub const GYRO_UI_FILT_ORD_MASK: u8 = 0b0000_1100;
    /// ACCEL_UI_FILT_ORD field (bits 4:3) of ACCEL_CONFIG1.
    pub const ACCEL_UI_FILT_ORD_MASK: u8 = 0b0001_1000;
    /// UI filter order value for 3rd order (2), before shifting.
    pub const UI_FILT_ORD_3RD: u8 = 2;
    /// UI filter bandwidth index 4: max(400 Hz, ODR) / 10.
    pub const UI_FILT_BW_DIV10: u8 = 4;
    /// AAF setting for a 42 Hz corner: DELT.
    pub const AAF_42HZ_DELT: u8 = 1;
    /// AAF setting for a 42 Hz corner: DELTSQR (12 bits).
    pub const AAF_42HZ_DELTSQR: u16 = 1;
    /// AAF setting for a 42 Hz corner: BITSHIFT.
    pub const AAF_42HZ_BITSHIFT: u8 = 15;
    /// What a data register holds when no sample is available.
    pub const NO_DATA: i16 = i16::MIN;
    /// `INT_CONFIG`: INT1 pulsed (a 100 µs pulse per sample:
    /// INT_CONFIG1's INT_TPULSE_DURATION at its reset value 0), push-pull, active high.
    pub const INT1_PULSED_PUSH_PULL_HIGH: u8 = 0b0000_0011;
    /// `INT_CONFIG1`: the INT_ASYNC_RESET bit.
    pub const INT_ASYNC_RESET: u8 = 0b0001_0000;
    /// `INT_SOURCE0`: data ready on INT1 only.
    pub const UI_DRDY_INT1_EN: u8 = 0b0000_1000;
    /// `SIGNAL_PATH_RESET`: FIFO_FLUSH.
    pub const FIFO_FLUSH: u8 = 0b0000_0010;
    /// `FIFO_CONFIG`: stream-to-FIFO mode (the oldest data go when full).
    pub const FIFO_STREAM: u8 = 0b0100_0000;
    /// `FIFO_CONFIG1`: accelerometer, gyro and temperature: packet 3.
    pub const FIFO_PACKET3: u8 = 0b0000_0111;
    /// Bytes of one packet 3 (section 6): header, accel x/y/z and gyro
    /// x/y/z as big-endian 16-bit words, temperature (1), timestamp (2).
    pub const PACKET3_LEN: usize = 16;
    /// Packet header bits (section 6, FIFO header): 7 HEADER_MSG (1: the FIFO is
    /// empty, no data), 6 HEADER_ACCEL, 5 HEADER_GYRO.
    pub const HEADER_MSG: u8 = 0x80;
    /// Header: accelerometer data present.
    pub const HEADER_ACCEL: u8 = 0x40;
    /// Header: gyro data present.
    pub const HEADER_GYRO: u8 = 0x20;
}

/// Wait after a soft reset before the next register access (datasheet: 1 ms).
pub const RESET_WAIT_US: u32 = 1_000;
/// Wait after switching the sensors on: the gyro needs 45 ms before its
/// output is valid (the accelerometer less); no register write for 200 µs.
pub const STARTUP_WAIT_US: u32 = 45_000;

/// Accelerometer full scale: ±16 g, the only range of this part that
/// covers the ±10 g the study needs.
pub const ACCEL_FS_SEL_16G: u8 = 0;
/// Accelerometer counts per g at ±16 g.
pub const ACCEL_COUNTS_PER_G: f32 = 2048.0;

/// Gyro full scale.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GyroRange {
    /// ±1000 deg/s.
    Dps1000,
    /// ±500 deg/s.
    Dps500,
}

impl GyroRange {
    const fn fs_sel(self) -> u8 {
        match self {
            Self::Dps1000 => 1,
            Self::Dps500 => 2,
        }
    }

    /// Counts per deg/s.
    #[must_use]
    pub const fn counts_per_dps(self) -> f32 {
        match self {
            Self::Dps1000 => 32.8,
            Self::Dps500 => 65.5,
        }
    }
}

/// Driver configuration. The accelerometer range, output rate and filters
/// are fixed (see the module documentation); the gyro range may be widened.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// Gyro full scale. Default ±500 deg/s.
    pub gyro_range: GyroRange,
}

impl Config {
    /// `base` with this sensor's datasheet sensitivities for the configured
    /// ranges (2048 LSB/g at ±16 g, 65.5 LSB/(deg/s) at ±500 deg/s).
    #[must_use]
    pub fn imu_config(&self, base: ImuConfig) -> ImuConfig {
        ImuConfig {
            accel_g_per_lsb: 1.0 / ACCEL_COUNTS_PER_G,
            gyro_dps_per_lsb: 1.0 / self.gyro_range.counts_per_dps(),
            ..base
        }
    }
}

impl Default for Config {
    fn default() -> Self {
        Self {
            gyro_range: GyroRange::Dps500,
        }
    }
}

/// What went wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum Error<E> {
    /// The SPI bus failed.
    Comm(E),
    /// `WHO_AM_I` read 0x00 or 0xFF, or a data burst read nothing else: no
    /// sensor on the bus (or no power).
    NoResponse,
    /// `WHO_AM_I` read this instead of 0x47: another part.
    WrongId(u8),
    /// The data registers hold the "no data" marker: the sensor is off or
    /// was reset.
    NotReady,
}

impl<E> Error<E> {
    /// How the sampler records it: a sensor that is absent, mute or not the
    /// right part does not respond (an IMU fault, status bit set); one with
    /// no data yet is stale.
    #[must_use]
    pub const fn sensor_error(&self) -> SensorError {
        match self {
            Self::Comm(_) | Self::NoResponse | Self::WrongId(_) => SensorError::NoResponse,
            Self::NotReady => SensorError::Stale,
        }
    }
}

/// One step of the configuration sequence.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Step {
    /// Write a register.
    Write(u8, u8),
    /// Replace the `mask` bits of a register, keeping the others.
    Modify(u8, u8, u8),
    /// Wait.
    WaitUs(u32),
}

/// The datasheet's configuration sequence after the identity check, with
/// `gyro_config0` (range and rate) for GYRO_CONFIG0.
const fn configuration(gyro_config0: u8) -> [Step; 23] {
    use reg::*;
    let [deltsqr_hi, deltsqr_lo] = AAF_42HZ_DELTSQR.to_be_bytes();
    let shift_and_hi = (AAF_42HZ_BITSHIFT << 4) | deltsqr_hi;
    [
        Step::Write(DEVICE_CONFIG, SOFT_RESET),
        Step::WaitUs(RESET_WAIT_US),
        // Anti-alias filters, banks 1 (gyro) and 2 (accel); the sensors are
        // off after the reset, as the filter registers require.
        Step::Write(REG_BANK_SEL, 1),
        Step::Write(GYRO_CONFIG_STATIC3, AAF_42HZ_DELT),
        Step::Write(GYRO_CONFIG_STATIC4, deltsqr_lo),
        Step::Write(GYRO_CONFIG_STATIC5, shift_and_hi),
        Step::Write(REG_BANK_SEL, 2),
        // ACCEL_AAF_DIS (bit 0) stays clear: the filter is on.
        Step::Write(ACCEL_CONFIG_STATIC2, AAF_42HZ_DELT << 1),
        Step::Write(ACCEL_CONFIG_STATIC3, deltsqr_lo),
        Step::Write(ACCEL_CONFIG_STATIC4, shift_and_hi),
        Step::Write(REG_BANK_SEL, 0),
        Step::Write(GYRO_CONFIG0, gyro_config0),
        Step::Write(
            ACCEL_CONFIG0,
            (ACCEL_FS_SEL_16G << FS_SEL_SHIFT) | ODR_100HZ,
        ),
        // The filter-order registers hold reserved bits: read-modify-write.
        Step::Modify(GYRO_CONFIG1, GYRO_UI_FILT_ORD_MASK, UI_FILT_ORD_3RD << 2),
        Step::Modify(ACCEL_CONFIG1, ACCEL_UI_FILT_ORD_MASK, UI_FILT_ORD_3RD << 3),
        Step::Write(
            GYRO_ACCEL_CONFIG0,
            (UI_FILT_BW_DIV10 << 4) | UI_FILT_BW_DIV10,
        ),
        // Every sample into the FIFO, and a data-ready pulse on INT1 for
        // each: the sampler times them on the MCU clock (`imu_clock`).
        Step::Write(FIFO_CONFIG1, FIFO_PACKET3),
        Step::Write(FIFO_CONFIG, FIFO_STREAM),
        Step::Write(INT_CONFIG, INT1_PULSED_PUSH_PULL_HIGH),
        Step::Modify(INT_CONFIG1, INT_ASYNC_RESET, 0),
        Step::Write(INT_SOURCE0, UI_DRDY_INT1_EN),
        Step::Write(PWR_MGMT0, PWR_GYRO_ACCEL_LOW_NOISE),
        Step::WaitUs(STARTUP_WAIT_US),
    ]
}

/// Bytes of one accel + gyro burst.
const DATA_LEN: usize = 12;

/// The driver. Owns its SPI device (chip select handled by the device).
#[derive(Debug)]
pub struct Icm42688<SPI> {
    spi: SPI,
    config: Config,
}

impl<SPI: SpiDevice> Icm42688<SPI> {
    /// A driver for the sensor on `spi`; nothing is sent until [`Self::init`].
    pub const fn new(spi: SPI, config: Config) -> Self {
        Self { spi, config }
    }

    /// Gives the SPI device back.
    pub fn release(self) -> SPI {
        self.spi
    }

    /// Checks the identity, resets the sensor and configures ranges, rate
    /// and filters, then switches both sensors on and waits until their
    /// output is valid. Safe to call again to recover from any error.
    ///
    /// # Errors
    /// [`Error::Comm`] on a bus error, [`Error::NoResponse`] or
    /// [`Error::WrongId`] when the sensor is not there.
    pub async fn init(&mut self, delay: &mut impl DelayNs) -> Result<(), Error<SPI::Error>> {
        use reg::*;
        match self.who_am_i().await? {
            WHO_AM_I_VALUE => {}
            0x00 | 0xFF => return Err(Error::NoResponse),
            other => return Err(Error::WrongId(other)),
        }
        let gyro_config0 = (self.config.gyro_range.fs_sel() << FS_SEL_SHIFT) | ODR_100HZ;
        // One loop over the table: a single await point per kind of step
        // keeps the async state machine (and the flash) small.
        for step in configuration(gyro_config0) {
            match step {
                Step::Write(register, value) => self.write(register, value).await?,
                Step::Modify(register, mask, bits) => self.modify(register, mask, bits).await?,
                Step::WaitUs(us) => delay.delay_us(us).await,
            }
        }
        Ok(())
    }

    /// Reads the identity register as it is, whatever part answers (the
    /// self-test reports the raw value). Works before [`Self::init`].
    ///
    /// # Errors
    /// [`Error::Comm`] on a bus error.
    pub async fn who_am_i(&mut self) -> Result<u8, Error<SPI::Error>> {
        // The MCU may have reset while the sensor was left in another bank.
        self.write(reg::REG_BANK_SEL, 0).await?;
        self.read_reg(reg::WHO_AM_I).await
    }

    /// Reads the latest accel and gyro sample (one 12-byte burst), in the
    /// sensor's axes and counts: scale with [`Config::imu_config`].
    ///
    /// # Errors
    /// [`Error::Comm`] on a bus error, [`Error::NotReady`] when the sensor
    /// has no data, [`Error::NoResponse`] when the bus reads as if nothing
    /// were on it.
    pub async fn read(&mut self) -> Result<RawImu, Error<SPI::Error>> {
        let mut raw = [0u8; DATA_LEN];
        self.read_regs(reg::ACCEL_DATA_X1, &mut raw).await?;
        if raw.iter().all(|&b| b == 0xFF) || raw.iter().all(|&b| b == 0x00) {
            return Err(Error::NoResponse);
        }
        words(&raw).ok_or(Error::NotReady)
    }

    /// Empties the FIFO (the samples of the start-up wait, whose data-ready
    /// pulses nobody timed).
    ///
    /// # Errors
    /// [`Error::Comm`] on a bus error.
    pub async fn flush_fifo(&mut self) -> Result<(), Error<SPI::Error>> {
        self.write(reg::SIGNAL_PATH_RESET, reg::FIFO_FLUSH).await
    }

    /// Whole samples waiting in the FIFO (FIFO_COUNTH/L over the packet
    /// size).
    ///
    /// # Errors
    /// [`Error::Comm`] on a bus error.
    pub async fn fifo_samples(&mut self) -> Result<u16, Error<SPI::Error>> {
        let mut count = [0u8; 2];
        self.read_regs(reg::FIFO_COUNTH, &mut count).await?;
        Ok(u16::from_be_bytes(count) / reg::PACKET3_LEN as u16)
    }

    /// Pops one sample from the FIFO; `Ok(None)` for a packet without both
    /// sensors' data or holding the "no data" marker (the sensor's first
    /// samples after power-up).
    ///
    /// # Errors
    /// [`Error::Comm`] on a bus error, [`Error::NoResponse`] when the bus
    /// reads as if nothing were on it.
    pub async fn fifo_sample(&mut self) -> Result<Option<RawImu>, Error<SPI::Error>> {
        use reg::*;
        let mut packet = [0u8; PACKET3_LEN];
        self.read_regs(FIFO_DATA, &mut packet).await?;
        if packet.iter().all(|&b| b == 0xFF) || packet.iter().all(|&b| b == 0x00) {
            return Err(Error::NoResponse);
        }
        let header = packet[0];
        if header & HEADER_MSG != 0
            || header & (HEADER_ACCEL | HEADER_GYRO) != HEADER_ACCEL | HEADER_GYRO
        {
            return Ok(None);
        }
        Ok(words(&packet[1..1 + DATA_LEN]))
    }

    async fn write(&mut self, register: u8, value: u8) -> Result<(), Error<SPI::Error>> {
        self.spi
            .write(&[register, value])
            .await
            .map_err(Error::Comm)
    }

    async fn read_regs(&mut self, first: u8, out: &mut [u8]) -> Result<(), Error<SPI::Error>> {
        self.spi
            .transaction(&mut [Operation::Write(&[first | reg::READ]), Operation::Read(out)])
            .await
            .map_err(Error::Comm)
    }

    async fn read_reg(&mut self, register: u8) -> Result<u8, Error<SPI::Error>> {
        let mut value = [0u8];
        self.read_regs(register, &mut value).await?;
        Ok(value[0])
    }

    async fn modify(&mut self, register: u8, mask: u8, bits: u8) -> Result<(), Error<SPI::Error>> {
        let old = self.read_reg(register).await?;
        self.write(register, (old & !mask) | (bits & mask)).await
    }
}

/// Six big-endian words (accel x/y/z, gyro x/y/z) as a sample; `None`
/// when one sensor's three words all hold the "no data" marker (it is off
/// or still starting: the gyro's first samples after power-up).
fn words(bytes: &[u8]) -> Option<RawImu> {
    let word = |i: usize| i16::from_be_bytes([bytes[2 * i], bytes[2 * i + 1]]);
    let sample = RawImu {
        accel: [word(0), word(1), word(2)],
        gyro: [word(3), word(4), word(5)],
    };
    let no_data = |axes: &[i16; 3]| axes.iter().all(|&w| w == reg::NO_DATA);
    (!no_data(&sample.accel) && !no_data(&sample.gyro)).then_some(sample)
}
