//! An ICM-42688-P behind an emulated SPI bus: the QEMU machine has the SPI
//! controller but no sensor on it, so the firmware's own driver
//! (`wobble_core::drivers::icm42688`) talks to this register file through
//! the `embedded-hal-async` `SpiDevice` trait instead.
//!
//! It answers as the datasheet describes the parts the driver uses:
//! `WHO_AM_I`, the bank select, a soft reset that clears the configuration,
//! and the 12 data registers, which hold the "no data" marker until both
//! sensors are switched on and then the replayed row's register bytes. The
//! scenario can kill the sensor (every byte reads 0xFF, as a bus with
//! nothing on it) or freeze its data registers.

use core::cell::RefCell;
use core::convert::Infallible;

use embassy_time::Instant;
use embedded_hal_async::spi::{ErrorType, Operation, SpiDevice};
use wobble_core::drivers::icm42688::reg;

use crate::replay::{Ride, IMU_DATA_LEN};
use crate::scenario::{within, Scenario};

/// Register banks the driver selects (0 to 2), 128 addresses each.
const BANKS: usize = 3;
/// `WHO_AM_I` and the data registers sit in bank 0.
const BANK0: usize = 0;

/// The emulated sensor.
pub struct EmulatedIcm42688 {
    ride: &'static RefCell<Ride>,
    scenario: &'static Scenario,
    regs: [[u8; 128]; BANKS],
    bank: usize,
    /// The data registers while frozen.
    frozen: Option<[u8; IMU_DATA_LEN]>,
}

impl EmulatedIcm42688 {
    /// A sensor after power-on, reading `ride`'s current row.
    pub fn new(ride: &'static RefCell<Ride>, scenario: &'static Scenario) -> Self {
        let mut s = Self {
            ride,
            scenario,
            regs: [[0; 128]; BANKS],
            bank: BANK0,
            frozen: None,
        };
        s.reset();
        s
    }

    fn reset(&mut self) {
        self.regs = [[0; 128]; BANKS];
        self.regs[BANK0][usize::from(reg::WHO_AM_I)] = reg::WHO_AM_I_VALUE;
        self.bank = BANK0;
    }

    fn dead(&self, now_ms: u64) -> bool {
        self.scenario
            .imu_dead_from_ms
            .is_some_and(|t| now_ms >= u64::from(t))
    }

    /// The 12 data registers as a read sees them now.
    fn data(&mut self, now_ms: u64) -> [u8; IMU_DATA_LEN] {
        let on = self.regs[BANK0][usize::from(reg::PWR_MGMT0)] & reg::PWR_GYRO_ACCEL_LOW_NOISE
            == reg::PWR_GYRO_ACCEL_LOW_NOISE;
        if !on {
            let [hi, lo] = reg::NO_DATA.to_be_bytes();
            return core::array::from_fn(|i| if i % 2 == 0 { hi } else { lo });
        }
        let live = self.ride.borrow().imu_regs().unwrap_or([0; IMU_DATA_LEN]);
        if within(self.scenario.imu_stuck_ms, now_ms) {
            *self.frozen.get_or_insert(live)
        } else {
            self.frozen = None;
            live
        }
    }

    fn read_from(&mut self, first: u8, out: &mut [u8], now_ms: u64) {
        if self.dead(now_ms) {
            out.fill(0xFF);
            return;
        }
        let data_start = usize::from(reg::ACCEL_DATA_X1);
        let data = (self.bank == BANK0).then(|| self.data(now_ms));
        for (i, b) in out.iter_mut().enumerate() {
            let addr = (usize::from(first) + i) % 128;
            *b = match (addr.checked_sub(data_start), data) {
                (Some(k), Some(d)) if k < IMU_DATA_LEN => d[k],
                _ if addr == usize::from(reg::REG_BANK_SEL) => self.bank as u8,
                _ => self.regs[self.bank][addr],
            };
        }
    }

    fn write_to(&mut self, first: u8, bytes: &[u8], now_ms: u64) {
        if self.dead(now_ms) {
            return;
        }
        for (i, &value) in bytes.iter().enumerate() {
            let addr = (usize::from(first) + i) % 128;
            if addr == usize::from(reg::REG_BANK_SEL) {
                self.bank = usize::from(value).min(BANKS - 1);
            } else if self.bank == BANK0
                && addr == usize::from(reg::DEVICE_CONFIG)
                && value & reg::SOFT_RESET != 0
            {
                self.reset();
            } else {
                self.regs[self.bank][addr] = value;
            }
        }
    }
}

impl ErrorType for EmulatedIcm42688 {
    type Error = Infallible;
}

impl SpiDevice for EmulatedIcm42688 {
    /// One chip-select frame: the first byte written is the address (bit 7
    /// set for a read); the rest of the frame reads or writes from there.
    async fn transaction(
        &mut self,
        operations: &mut [Operation<'_, u8>],
    ) -> Result<(), Infallible> {
        let now_ms = Instant::now().as_millis();
        let mut addr: Option<(u8, bool)> = None;
        for op in operations {
            match op {
                Operation::Write(bytes) => {
                    let (rest, (first, read)) = match addr {
                        Some(a) => (*bytes, a),
                        None => match bytes.split_first() {
                            Some((&a, rest)) => (rest, (a & !reg::READ, a & reg::READ != 0)),
                            None => continue,
                        },
                    };
                    if !read {
                        self.write_to(first, rest, now_ms);
                    }
                    addr = Some((first.wrapping_add(rest.len() as u8), read));
                }
                Operation::Read(out) => {
                    if let Some((first, true)) = addr {
                        self.read_from(first, out, now_ms);
                        addr = Some((first.wrapping_add(out.len() as u8), true));
                    } else {
                        out.fill(0xFF);
                    }
                }
                Operation::Transfer(_, _)
                | Operation::TransferInPlace(_)
                | Operation::DelayNs(_) => {}
            }
        }
        Ok(())
    }
}
