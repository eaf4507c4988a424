//! The GPS receiver on USART2: a DMA ring buffer for what it sends, the
//! transmit side for the set-up commands, and the baud rate switch. The
//! bring-up decisions (which baud, which commands, whether they worked) are
//! the core's `drivers::gnss_bringup`, driven by `app::gps_setup`.

use embassy_stm32::mode::Async;
use embassy_stm32::usart::{self, RingBufferedUartRx, Uart, UartTx};
use wobble_core::app::gps_setup::GpsLink;
use wobble_core::app::ports::GpsPort;
use wobble_core::drivers::gnss_bringup::PROBE_BAUDS;

use crate::pins::{GpsPins, Irqs};

/// DMA ring size: 115 200 baud is 11.5 bytes/ms, so 1 KiB holds 89 ms,
/// far more than the GPS task's executor is ever kept from running.
pub const RING_BYTES: usize = 1024;

/// Both directions of the receiver's UART.
pub struct GpsAdapter {
    tx: UartTx<'static, Async>,
    rx: RingBufferedUartRx<'static>,
}

impl GpsAdapter {
    /// USART2 at the receivers' usual power-up rate (the bring-up finds
    /// theirs), receiving into `ring`.
    pub fn new(pins: GpsPins, ring: &'static mut [u8; RING_BYTES]) -> Self {
        let mut config = usart::Config::default();
        config.baudrate = PROBE_BAUDS[0];
        let uart = defmt::unwrap!(Uart::new(
            pins.uart,
            pins.rx,
            pins.tx,
            pins.tx_dma,
            pins.rx_dma,
            Irqs,
            config
        )
        .ok());
        let (tx, rx) = uart.split();
        let mut rx = rx.into_ring_buffered(ring);
        rx.start_uart();
        Self { tx, rx }
    }
}

impl GpsPort for GpsAdapter {
    async fn read(&mut self, buf: &mut [u8]) -> usize {
        // The GPS task asks at least every 100 ms, bytes or not.
        crate::watchdog::GPS.beat();
        loop {
            match self.rx.read(buf).await {
                Ok(n) if n > 0 => return n,
                Ok(_) => {}
                // Overrun or line noise: the bytes are gone, the core's
                // NMEA path counts the broken sentence; the ring restarts.
                Err(e) => defmt::debug!("GPS UART: {}", e),
            }
        }
    }
}

impl GpsLink for GpsAdapter {
    fn set_baud(&mut self, baud: u32) {
        // One baud rate register serves both directions.
        if self.tx.set_baudrate(baud).is_err() {
            defmt::warn!("GPS: cannot set {} baud", baud);
        }
    }

    async fn send(&mut self, bytes: &[u8]) {
        if self.tx.write(bytes).await.is_err() || self.tx.flush().await.is_err() {
            defmt::warn!("GPS: set-up command not sent");
        }
    }
}
