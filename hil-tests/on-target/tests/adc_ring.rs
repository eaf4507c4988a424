//! The steering adapter on the real ADC1 + DMA ring: the frames after a
//! stall as long as an IMU re-initialisation each get their own 10 ms of
//! samples and none is lost; an overrun (the DMA stream stopped under the
//! converter) is reported once and recovered from; a converter that stops
//! without an overrun is re-initialised.
#![no_std]
#![no_main]

use defmt_rtt as _;

#[cfg(test)]
#[embedded_test::tests]
mod tests {
    use embassy_stm32::adc::{Adc, AdcChannel, Exten, SampleTime, CONTINUOUS};
    use embassy_stm32::pac;
    use embassy_time::{block_for, Duration, Instant, Timer};
    use wobble_core::adc_ring::DRY_US;
    use wobble_core::app::ports::{SensorError, SteeringPort};
    use wobble_core::app::sampler::FRAME_PERIOD_US;
    use wobble_core::stall::LONGEST_STALL_US;
    use wobble_core::steering::{Steering, SteeringCalibration};
    use wobble_stm32f405::adapters::steering::{self, SteeringAdapter, CONVERSIONS_HZ};
    use wobble_stm32f405::pins::Irqs;

    fn adapter() -> SteeringAdapter {
        let (board, _) = wobble_on_target::board();
        let pins = board.steering;
        let adc = Adc::new(pins.adc).into_ring_buffered(
            pins.dma,
            steering::ring(),
            Irqs,
            [(pins.wiper.degrade_adc(), SampleTime::CYCLES480)].into_iter(),
            CONTINUOUS,
            Exten::DISABLED,
        );
        let channel = defmt::unwrap!(Steering::try_new(SteeringCalibration::DEFAULT).ok());
        SteeringAdapter::new(adc, channel)
    }

    #[test]
    async fn the_frames_after_a_stall_each_get_their_own_10_ms_and_none_is_lost() {
        let mut steering = adapter();
        Timer::after_millis(20).await;
        for _ in 0..3 {
            // Three rounds: the ring wraps in between.
            defmt::assert!(steering.read(0).await.is_ok());
            let start = Instant::now();
            // The sampler stalls (busy, as an awaited SPI re-init would
            // keep the ticker from firing).
            block_for(Duration::from_micros(u64::from(LONGEST_STALL_US)));
            // The ticker fires the missed ticks back to back.
            let missed = u64::from(LONGEST_STALL_US) / FRAME_PERIOD_US;
            let mut total = 0;
            for k in 1..=missed {
                let scheduled = start + Duration::from_micros(k * FRAME_PERIOD_US);
                let late = Instant::now().saturating_duration_since(scheduled);
                defmt::assert!(steering.read(late.as_micros()).await.is_ok());
                let n = steering.last_samples();
                defmt::assert!((415..=440).contains(&n), "frame {} got {} samples", k, n);
                total += n;
            }
            // An on-time read takes the rest.
            defmt::assert!(steering.read(0).await.is_ok());
            total += steering.last_samples();
            let expected = Instant::now().duration_since(start).as_micros()
                * u64::from(CONVERSIONS_HZ)
                / 1_000_000;
            let diff = (total as u64).abs_diff(expected);
            defmt::assert!(diff <= 3, "{} samples, {} converted", total, expected);
        }
    }

    #[test]
    async fn an_overrun_is_reported_once_and_the_adc_restarts() {
        let mut steering = adapter();
        Timer::after_millis(20).await;
        defmt::assert!(steering.read(0).await.is_ok());
        // Stop the DMA stream under the running converter: the next
        // conversion finds its predecessor unread.
        pac::DMA2.st(4).cr().modify(|w| w.set_en(false));
        Timer::after_millis(1).await;
        defmt::assert!(pac::ADC1.sr().read().ovr(), "no overrun provoked");
        defmt::assert_eq!(steering.read(0).await, Err(SensorError::Overrun));
        Timer::after_millis(10).await;
        defmt::assert!(steering.read(0).await.is_ok(), "not restarted");
        defmt::assert!((415..=440).contains(&steering.last_samples()));
        defmt::assert!(!pac::ADC1.sr().read().ovr());
        defmt::assert_eq!(steering.recovery_stats().restarts, 1);
    }

    #[test]
    async fn a_converter_that_stops_without_an_overrun_is_reinitialised() {
        let mut steering = adapter();
        Timer::after_millis(20).await;
        defmt::assert!(steering.read(0).await.is_ok());
        // Power the converter down under the driver: no conversion, no
        // overrun, nothing in the ring.
        pac::ADC1.cr2().modify(|w| w.set_adon(false));
        let mut stale = 0;
        let frames = DRY_US / FRAME_PERIOD_US + 3;
        for _ in 0..frames {
            Timer::after_micros(FRAME_PERIOD_US).await;
            if steering.read(0).await == Err(SensorError::Stale) {
                stale += 1;
            }
        }
        defmt::assert_eq!(steering.recovery_stats().reinits, 1);
        defmt::assert!(stale >= 2, "{} stale frames", stale);
        defmt::assert!(steering.read(0).await.is_ok(), "not re-initialised");
    }
}
