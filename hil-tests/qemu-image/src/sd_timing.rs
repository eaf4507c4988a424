//! The virtual time a microSD card takes per block on the board's bus. The
//! limits are the SD specification's (Physical Layer Simplified
//! Specification, 4.6.2 "Read, Write and Erase Timeout Conditions"): a
//! read may take up to 100 ms before the card sends the block, a written
//! block may keep the card busy up to 250 ms (SDSC and SDHC; 500 ms for
//! SDXC). Real cards are mostly far quicker and stall now and then while
//! they reorganise their flash; the model draws both from a seeded
//! generator, so a run reproduces:
//!
//! | per block | time |
//! |---|---|
//! | transfer | command, token, 512 bytes, CRC and response, about 522 bytes at the board's 21 MHz SPI clock: 199 µs |
//! | read access | 0.3-1 ms; one read in 256: 10-100 ms |
//! | write busy | 0.5-2 ms; one write in 128: 25-250 ms |

use core::cell::Cell;

use embassy_time::{Duration, Instant};

/// One block's transfer on the bus.
const TRANSFER: Duration = Duration::from_micros(522 * 8 * 1_000_000 / 21_000_000);
/// The specification's longest read access.
const READ_LIMIT_US: u32 = 100_000;
/// The specification's longest write busy (SDSC, SDHC).
const WRITE_LIMIT_US: u32 = 250_000;

/// The card's timing generator.
pub struct SdTiming {
    state: Cell<u32>,
}

impl SdTiming {
    /// A generator seeded with `seed` (0 is taken as 1).
    pub fn new(seed: u32) -> Self {
        Self {
            state: Cell::new(seed.max(1)),
        }
    }

    /// xorshift32: the run's only randomness, so a seed reproduces it.
    fn next(&self) -> u32 {
        let mut x = self.state.get();
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.state.set(x);
        x
    }

    /// A time in `[lo_us, hi_us]`.
    fn between(&self, lo_us: u32, hi_us: u32) -> Duration {
        Duration::from_micros(u64::from(lo_us + self.next() % (hi_us - lo_us + 1)))
    }

    /// The time before a read block has arrived.
    pub fn read(&self) -> Duration {
        let access = if self.next().is_multiple_of(256) {
            self.between(10_000, READ_LIMIT_US)
        } else {
            self.between(300, 1_000)
        };
        TRANSFER + access
    }

    /// A written block's transfer and the busy time after it.
    pub fn write(&self) -> (Duration, Duration) {
        let busy = if self.next().is_multiple_of(128) {
            self.between(25_000, WRITE_LIMIT_US)
        } else {
            self.between(500, 2_000)
        };
        (TRANSFER, busy)
    }
}

/// Where inside a block write the power goes.
pub struct CutPoint {
    /// Time from the start of the write.
    pub after: Duration,
    transfer: Duration,
    busy: Duration,
}

impl CutPoint {
    /// `permille` thousandths into the write's transfer and busy time.
    pub fn new(transfer: Duration, busy: Duration, permille: u32) -> Self {
        let total = (transfer + busy).as_micros();
        Self {
            after: Duration::from_micros(total * u64::from(permille.min(1000)) / 1000),
            transfer,
            busy,
        }
    }

    /// How many of the block's `len` bytes the card had programmed: none
    /// while the block was still on the bus (the card discards a partial
    /// block), then in proportion to the busy time gone.
    pub fn programmed_bytes(&self, len: usize) -> usize {
        let Some(programming) = self.after.checked_sub(self.transfer) else {
            return 0;
        };
        let busy_us = self.busy.as_micros().max(1);
        let done = (programming.as_micros().min(busy_us) * len as u64) / busy_us;
        usize::try_from(done).unwrap_or(len).min(len)
    }
}

/// Instructions per µs of virtual time: the harness runs QEMU with an
/// instruction clock of 8 ns per instruction (`-icount shift=3`).
const INSTRUCTIONS_PER_US: u64 = 125;

/// Waits in thread mode until `deadline`, as the board's writer waits on a
/// busy card: asleep between SysTick ticks while more than a tick is left,
/// then counting instructions to the exact time (reading the clock in a
/// spin would make QEMU re-translate code on every timer register access,
/// ten times slower).
pub fn busy_until(deadline: Instant) {
    loop {
        let now = Instant::now();
        if now >= deadline {
            return;
        }
        let left = deadline - now;
        if left <= Duration::from_millis(1) {
            let n = left.as_micros() * INSTRUCTIONS_PER_US;
            cortex_m::asm::delay(u32::try_from(n).unwrap_or(u32::MAX));
            return;
        }
        cortex_m::asm::wfi();
    }
}
