//! The steering adapter on the real ADC1 + DMA ring: a stall as long as an
//! IMU re-initialisation costs no sample, and an overrun (the DMA stream
//! stopped under the converter) is reported once and recovered from.
#![no_std]
#![no_main]

use defmt_rtt as _;

#[cfg(test)]
#[embedded_test::tests]
mod tests {
    use embassy_stm32::adc::{Adc, AdcChannel, Exten, SampleTime, CONTINUOUS};
    use embassy_stm32::pac;
    use embassy_time::Timer;
    use static_cell::StaticCell;
    use wobble_core::app::ports::{SensorError, SteeringPort};
    use wobble_core::stall::LONGEST_STALL_US;
    use wobble_core::steering::{Steering, SteeringCalibration};
    use wobble_stm32f405::adapters::steering::{SteeringAdapter, DMA_SAMPLES};
    use wobble_stm32f405::pins::Irqs;

    static RING: StaticCell<[u16; DMA_SAMPLES]> = StaticCell::new();

    fn adapter() -> SteeringAdapter {
        let (board, _) = wobble_on_target::board();
        let pins = board.steering;
        let adc = Adc::new(pins.adc).into_ring_buffered(
            pins.dma,
            RING.init([0; DMA_SAMPLES]),
            Irqs,
            [(pins.wiper.degrade_adc(), SampleTime::CYCLES480)].into_iter(),
            CONTINUOUS,
            Exten::DISABLED,
        );
        let channel = defmt::unwrap!(Steering::try_new(SteeringCalibration::DEFAULT).ok());
        SteeringAdapter::new(adc, channel)
    }

    #[test]
    async fn a_stall_as_long_as_an_imu_reinit_loses_no_frame() {
        let mut steering = adapter();
        Timer::after_millis(20).await;
        defmt::assert!(steering.read().await.is_ok());
        for _ in 0..10 {
            Timer::after_micros(u64::from(LONGEST_STALL_US)).await;
            defmt::assert!(steering.read().await.is_ok(), "stale after a stall");
        }
    }

    #[test]
    async fn an_overrun_is_reported_once_and_the_adc_restarts() {
        let mut steering = adapter();
        Timer::after_millis(20).await;
        defmt::assert!(steering.read().await.is_ok());
        // Stop the DMA stream under the running converter: the next
        // conversion finds its predecessor unread.
        pac::DMA2.st(4).cr().modify(|w| w.set_en(false));
        Timer::after_millis(1).await;
        defmt::assert!(pac::ADC1.sr().read().ovr(), "no overrun provoked");
        defmt::assert_eq!(steering.read().await, Err(SensorError::Overrun));
        Timer::after_millis(20).await;
        defmt::assert!(steering.read().await.is_ok(), "not restarted");
        defmt::assert!(!pac::ADC1.sr().read().ovr());
    }
}
