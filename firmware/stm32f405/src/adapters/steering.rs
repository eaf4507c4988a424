//! The steering potentiometer: ADC1 converting continuously into a DMA ring
//! buffer; each frame averages the samples it is owed through the core's
//! calibration. Which samples those are, and when the converter needs a
//! restart or a re-initialisation, is the core's `adc_ring`; here, only
//! the ring reads and the register sequences.

use embassy_stm32::adc::RingBufferedAdc;
use embassy_stm32::pac;
use embassy_stm32::peripherals::ADC1;
use embassy_time::Instant;
use static_cell::StaticCell;
use wobble_core::adc_ring::{OverrunRecovery, Recovery, RecoveryStats, SampleBacklog};
use wobble_core::app::ports::{SensorError, SteeringPort, SteeringSample};
use wobble_core::stall;
use wobble_core::steering::Steering;

/// Conversions per second: 21 MHz ADC clock / (480 + 12 cycles), 427 per
/// 10 ms frame (see `firmware/docs/board.md`).
pub const CONVERSIONS_HZ: u32 = 21_000_000 / 492;
/// DMA ring: the sampler's longest stall (an IMU re-initialisation, 46 ms,
/// plus a frame and margin: 66 ms, 2818 samples). The frames after a stall
/// share what it holds, each its own 10 ms (`wobble_core::adc_ring`).
pub const DMA_SAMPLES: usize = stall::ring_samples(CONVERSIONS_HZ, 2);
/// The DMA stream of the ring (DMA2 stream 4, `pins.rs`).
const STREAM: usize = 4;
// The ring's length goes into the 16-bit NDTR register.
const _: () = assert!(DMA_SAMPLES <= u16::MAX as usize);

static RING: StaticCell<[u16; DMA_SAMPLES]> = StaticCell::new();
/// What the frames after a stall are still owed (as large as the ring).
static BACKLOG: StaticCell<[u16; DMA_SAMPLES]> = StaticCell::new();

/// The DMA ring for `RingBufferedAdc` (once per boot).
pub fn ring() -> &'static mut [u16; DMA_SAMPLES] {
    RING.init([0; DMA_SAMPLES])
}

/// ADC ring buffer plus the core's steering channel.
pub struct SteeringAdapter {
    adc: RingBufferedAdc<'static, ADC1>,
    channel: Steering,
    /// Samples taken from the ring and owed to frames still to come.
    backlog: SampleBacklog<'static>,
    recovery: OverrunRecovery,
    /// Lowest and highest raw count of the last frame (the self-test's).
    last_range: Option<(u16, u16)>,
    /// Samples the last frame got.
    last_samples: usize,
}

impl SteeringAdapter {
    /// Starts the conversions of `adc` (made on [`ring`]). Once per boot:
    /// the backlog is this module's static.
    pub fn new(mut adc: RingBufferedAdc<'static, ADC1>, channel: Steering) -> Self {
        adc.start();
        Self {
            adc,
            channel,
            backlog: SampleBacklog::new(BACKLOG.init([0; DMA_SAMPLES])),
            recovery: OverrunRecovery::new(),
            last_range: None,
            last_samples: 0,
        }
    }

    /// Lowest and highest raw ADC count of the last frame read.
    pub fn last_range(&self) -> Option<(u16, u16)> {
        self.last_range
    }

    /// How many samples the last frame read got (427 on time, at 42.7 kHz).
    pub fn last_samples(&self) -> usize {
        self.last_samples
    }

    /// Restarts and re-initialisations so far.
    pub fn recovery_stats(&self) -> RecoveryStats {
        self.recovery.stats()
    }

    /// After an overrun (OVR: a conversion not taken by the DMA in time) the
    /// ADC issues no more DMA requests. RM0090 13.8.1: re-initialise the
    /// DMA (destination address and NDTR), clear OVR, trigger; with DDS
    /// set, the ADC's DMA bit is cleared and set again so its requests
    /// start afresh (13.8.1, "DMA mode").
    fn restart(&mut self) {
        let stream = pac::DMA2.st(STREAM);
        self.adc.stop();
        // RM0090 10.3.17: the stream may be reprogrammed once EN reads 0
        // (a transfer in progress completes first: a few bus cycles).
        for _ in 0..10_000 {
            if !stream.cr().read().en() {
                break;
            }
        }
        // M0AR is untouched and reloaded on enable; NDTR is rewound.
        stream.ndtr().write(|w| w.set_ndt(DMA_SAMPLES as u16));
        // HIFCR (streams 4-7): clear the error flags; the half and full
        // transfer flags are the driver's interrupt's.
        pac::DMA2.ifcr(1).write(|w| {
            w.set_teif(0, true);
            w.set_dmeif(0, true);
            w.set_feif(0, true);
        });
        // The ring's indices follow the rewound stream.
        self.adc.clear();
        self.backlog.clear();
        pac::ADC1.cr2().modify(|w| w.set_dma(false));
        pac::ADC1.cr2().modify(|w| w.set_dma(true));
        pac::ADC1.sr().modify(|w| w.set_ovr(false));
        // Stream enable and SWSTART.
        self.adc.start();
    }

    /// The converter gave nothing for `adc_ring::DRY_US`: powered down and
    /// up again (ADON; its sequence and sample time registers are kept),
    /// the stabilisation time (t_STAB, 3 µs at most) waited, then the
    /// restart sequence.
    fn reinit(&mut self) {
        pac::ADC1.cr2().modify(|w| w.set_adon(false));
        pac::ADC1.cr2().modify(|w| w.set_adon(true));
        embassy_time::block_for(embassy_time::Duration::from_micros(10));
        self.restart();
    }
}

impl SteeringPort for SteeringAdapter {
    async fn read(&mut self, late_us: u64) -> Result<SteeringSample, SensorError> {
        let now_us = Instant::now().as_micros();
        let overrun = pac::ADC1.sr().read().ovr();
        let new = if overrun {
            0
        } else {
            // Oldest first into the backlog's free space, which holds a
            // whole ring: nothing the ring still has is skipped.
            let n = self.adc.read_latest(self.backlog.spare());
            self.backlog.filled(n);
            n
        };
        match self.recovery.frame(now_us, overrun, new) {
            Recovery::None => {}
            Recovery::Restart => {
                defmt::warn!("steering ADC overrun: restarted");
                self.restart();
                return Err(SensorError::Overrun);
            }
            Recovery::Reinit => {
                defmt::warn!("steering ADC gives no samples: re-initialised");
                self.reinit();
            }
        }
        let owed = self.backlog.take_owed(late_us, CONVERSIONS_HZ);
        let samples = owed.samples();
        self.last_samples = samples.len();
        self.last_range = samples
            .iter()
            .min()
            .zip(samples.iter().max())
            .map(|(&lo, &hi)| (lo, hi));
        self.channel.push_all(samples);
        drop(owed);
        // No conversion owed to this frame: the ring stopped (or a frame
        // read twice within a conversion).
        self.channel.take().ok_or(SensorError::Stale)
    }
}
