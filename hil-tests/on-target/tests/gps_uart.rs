//! The GPS adapter on the real USART2 + DMA ring, TX looped back to RX:
//! a 20 Hz stream of RMC + GGA at 115 200 baud arrives whole, and so does
//! a 1 Hz stream at 9600 after a baud switch.
#![no_std]
#![no_main]

use defmt_rtt as _;

#[cfg(test)]
#[embedded_test::tests]
mod tests {
    use embassy_time::{Duration, Instant};
    use wobble_core::app::gps_setup::GpsLink;
    use wobble_core::app::ports::GpsPort;
    use wobble_core::drivers::gnss_bringup::SentenceCounter;
    use wobble_stm32f405::adapters::gps::GpsAdapter;

    const RMC: &[u8] = b"$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A\r\n";
    const GGA: &[u8] = b"$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n";

    fn port() -> GpsAdapter {
        let (board, _) = wobble_on_target::board();
        GpsAdapter::new(board.gps)
    }

    /// Sends `epochs` epochs at `hz`, reading back as it goes.
    async fn stream(port: &mut GpsAdapter, epochs: u32, hz: u64) -> SentenceCounter {
        let mut counter = SentenceCounter::new();
        let mut buf = [0u8; 64];
        let period = Duration::from_micros(1_000_000 / hz);
        for _ in 0..epochs {
            let next = Instant::now() + period;
            port.send(RMC).await;
            port.send(GGA).await;
            while Instant::now() < next {
                let n = embassy_time::with_deadline(next, port.read(&mut buf))
                    .await
                    .unwrap_or(0);
                counter.feed(&buf[..n]);
            }
        }
        counter
    }

    #[test]
    async fn twenty_hz_at_115200_arrives_whole() {
        let mut port = port();
        port.set_baud(115_200);
        let heard = stream(&mut port, 40, 20).await.heard();
        defmt::assert_eq!((heard.rmc, heard.gga, heard.rejected), (40, 40, 0));
    }

    #[test]
    async fn one_hz_at_9600_after_a_baud_switch() {
        let mut port = port();
        port.set_baud(115_200);
        port.set_baud(9_600);
        let heard = stream(&mut port, 3, 1).await.heard();
        // The first sentence after the switch may be cut.
        defmt::assert!(heard.rmc + heard.gga >= 5);
    }
}
