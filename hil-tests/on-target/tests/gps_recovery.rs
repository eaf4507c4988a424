//! The board's GPS task (`app::gps::run_link`) on the real USART2 + DMA
//! ring, against a receiver played by USART1: a MediaTek-like receiver at
//! 9600 baud, 1 Hz, that takes `PMTK251,115200` and `PMTK220,50`, and that
//! browns out 10 s after its set-up (back at 9600, 1 Hz, its RAM settings
//! gone). The task must notice the loss (GPS fault 9), bring it up again
//! and log 20 Hz fixes within 10 s of the reset.
//!
//! Wiring: PA9 (USART1 TX) to PA3 (GPS RX), PA2 (GPS TX) to PA10 (USART1
//! RX); the `gps_uart` loop-back PA2-PA3 removed.
#![no_std]
#![no_main]

use defmt_rtt as _;

#[cfg(test)]
#[embedded_test::tests]
mod tests {
    use embassy_futures::select::{select, Either};
    use embassy_stm32::mode::Async;
    use embassy_stm32::peripherals::{DMA2_CH5, DMA2_CH7, PA10, PA9, USART1};
    use embassy_stm32::usart::{self, Uart};
    use embassy_stm32::{bind_interrupts, dma};
    use embassy_time::{Duration, Instant, Timer};
    use wobble_core::app::gps::run_link;
    use wobble_core::channels::{RecordQueue, SharedStatus};
    use wobble_core::drivers::gnss_bringup::FAULT_RECEIVER_LOST;
    use wobble_core::format::{FaultSource, Record};
    use wobble_stm32f405::adapters::gps::GpsAdapter;

    bind_interrupts!(struct PlayerIrqs {
        USART1 => usart::InterruptHandler<USART1>;
        DMA2_STREAM5 => dma::InterruptHandler<DMA2_CH5>;
        DMA2_STREAM7 => dma::InterruptHandler<DMA2_CH7>;
    });

    static QUEUE: RecordQueue = RecordQueue::new();
    static SHARED: SharedStatus = SharedStatus::new();

    const RMC: &[u8] = b"$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A\r\n";
    const GGA: &[u8] = b"$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n";
    /// After its set-up the receiver runs this long, then browns out.
    const RESET_AFTER_S: u64 = 10;

    /// The played receiver: sends RMC + GGA at its rate and baud, applies
    /// the baud and rate commands it hears, and resets once, `RESET_AFTER_S`
    /// after it was first switched to 20 Hz, noting when in `reset_at`.
    /// Runs until the test ends.
    async fn receiver(uart: &mut Uart<'static, Async>, reset_at: &mut Option<Instant>) -> ! {
        let mut hz = 1u64;
        let mut configured_at = None;
        let mut cmd = [0u8; 128];
        loop {
            let next = Instant::now() + Duration::from_micros(1_000_000 / hz);
            if uart.write(RMC).await.is_err() || uart.write(GGA).await.is_err() {
                defmt::warn!("receiver: write failed");
            }
            while Instant::now() < next {
                let Ok(Ok(n)) =
                    embassy_time::with_deadline(next, uart.read_until_idle(&mut cmd)).await
                else {
                    continue;
                };
                let heard = cmd.get(..n).unwrap_or_default();
                let has = |needle: &[u8]| heard.windows(needle.len()).any(|w| w == needle);
                if has(b"PMTK251,115200") {
                    defmt::unwrap!(uart.set_baudrate(115_200).ok());
                }
                if has(b"PMTK220,50") {
                    hz = 20;
                    configured_at.get_or_insert(Instant::now());
                }
            }
            let due =
                configured_at.is_some_and(|t| t.elapsed() >= Duration::from_secs(RESET_AFTER_S));
            if due && reset_at.is_none() {
                // Brown-out: back to the power-up settings.
                hz = 1;
                defmt::unwrap!(uart.set_baudrate(9_600).ok());
                *reset_at = Some(Instant::now());
                defmt::info!("receiver: reset to 9600 baud, 1 Hz");
            }
        }
    }

    #[test]
    async fn a_receiver_reset_to_9600_is_back_at_20_hz_within_10_s() {
        let (board, _) = wobble_on_target::board();
        let mut port = GpsAdapter::new(board.gps);
        let mut config = usart::Config::default();
        config.baudrate = 9_600;
        // SAFETY: USART1, PA9, PA10 and DMA2 streams 5 and 7 are in no role
        // of the board's pin map.
        let (uart, tx, rx, tx_dma, rx_dma) = unsafe {
            (
                USART1::steal(),
                PA9::steal(),
                PA10::steal(),
                DMA2_CH7::steal(),
                DMA2_CH5::steal(),
            )
        };
        let mut player =
            defmt::unwrap!(Uart::new(uart, rx, tx, tx_dma, rx_dma, PlayerIrqs, config).ok());
        let mut reset_at = None;
        let mut log = |step: &_| defmt::info!("GPS set-up: {}", step);
        let task = run_link(&mut port, &QUEUE, &SHARED, &mut log);
        let watch = async {
            let end = Instant::now() + Duration::from_secs(60);
            let (mut lost, mut fixes_after) = (None, 0u32);
            while Instant::now() < end && fixes_after < 20 {
                while let Some(rec) = QUEUE.try_pop() {
                    match rec {
                        Record::Fault(f)
                            if f.source == FaultSource::Gps && f.code == FAULT_RECEIVER_LOST =>
                        {
                            lost = Some(Instant::now());
                        }
                        Record::Gps(_) if lost.is_some() => fixes_after += 1,
                        _ => {}
                    }
                }
                Timer::after_millis(10).await;
            }
            (lost, fixes_after, Instant::now())
        };
        let ((lost, fixes_after, back), _) =
            match select(watch, select(task, receiver(&mut player, &mut reset_at))).await {
                Either::First(out) => (out, ()),
                Either::Second(_) => defmt::panic!("the GPS task ended"),
            };
        let reset = defmt::unwrap!(reset_at, "the receiver never reached 20 Hz");
        defmt::assert!(lost.is_some(), "no GPS fault 9 after the reset");
        defmt::assert_eq!(fixes_after, 20, "too few fixes after the loss");
        let took = back.duration_since(reset);
        // 20 fixes at 20 Hz take 1 s of the 10.
        defmt::assert!(
            took < Duration::from_secs(10),
            "back {} ms after the reset",
            took.as_millis()
        );
    }
}
