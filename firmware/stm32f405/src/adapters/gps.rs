//! The GPS receiver on USART2: a DMA ring buffer for what it sends, the
//! transmit side for the set-up commands, and the baud rate switch. The
//! bring-up decisions (which baud, which commands, whether they worked) are
//! the core's `drivers::gnss_bringup`, driven by `app::gps_setup`; losing
//! and finding the receiver again is `app::gps::run_link`'s.
//!
//! embassy-stm32 0.6's ring-buffered receiver turns any error flag of the
//! status register (parity, framing, noise, overrun) into an error return,
//! stops the ring, and restarts it at the next read, losing what it held.
//! So the RX pin (PA3) is pulled up (an unplugged receiver leaves the line
//! idle, not floating), and the UART samples each bit once (ONEBIT, its
//! `assume_noise_free`): the noise flag is never raised, and a noisy bit
//! reaches the NMEA checksum, which rejects its sentence alone.

use embassy_stm32::gpio::Pull;
use embassy_stm32::mode::Async;
use embassy_stm32::usart::{self, RingBufferedUartRx, Uart, UartTx};
use static_cell::StaticCell;
use wobble_core::app::gps_setup::GpsLink;
use wobble_core::app::ports::GpsPort;
use wobble_core::drivers::gnss_bringup::PROBE_BAUDS;

use crate::pins::{GpsPins, Irqs};

/// DMA ring size: 115 200 baud is 11.5 bytes/ms, so 1 KiB holds 89 ms,
/// far more than the GPS task's executor is ever kept from running.
pub const RING_BYTES: usize = 1024;

static RING: StaticCell<[u8; RING_BYTES]> = StaticCell::new();
static STAGED: StaticCell<[u8; RING_BYTES]> = StaticCell::new();

/// Both directions of the receiver's UART.
pub struct GpsAdapter {
    tx: UartTx<'static, Async>,
    rx: RingBufferedUartRx<'static>,
    /// Everything the ring held at the last wake-up (a read takes it all,
    /// so the bytes still to hand out are known: [`GpsPort::pending`]).
    staged: &'static mut [u8; RING_BYTES],
    staged_len: usize,
    handed: usize,
}

impl GpsAdapter {
    /// USART2 at the receivers' usual power-up rate (the bring-up finds
    /// theirs), receiving into the DMA ring, each wake-up's bytes staged
    /// until the GPS task has taken them. Once per boot: the buffers are
    /// this module's statics (so the adapter stays small in its task).
    pub fn new(pins: GpsPins) -> Self {
        let ring = RING.init([0; RING_BYTES]);
        let staged = STAGED.init([0; RING_BYTES]);
        let mut config = usart::Config::default();
        config.baudrate = PROBE_BAUDS[0];
        config.rx_pull = Pull::Up;
        config.assume_noise_free = true;
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
        Self {
            tx,
            rx,
            staged,
            staged_len: 0,
            handed: 0,
        }
    }
}

impl GpsPort for GpsAdapter {
    async fn read(&mut self, buf: &mut [u8]) -> usize {
        // The GPS task asks at least every 100 ms, bytes or not.
        crate::watchdog::GPS.beat();
        while self.handed == self.staged_len {
            // Cancel-safe: until it returns, the bytes stay in the ring.
            match self.rx.read(&mut self.staged[..]).await {
                Ok(n) => {
                    self.staged_len = n;
                    self.handed = 0;
                }
                // A framing error (a receiver at another baud) or an
                // overrun: the bytes are gone, the core's NMEA path counts
                // the broken sentence; the ring restarts.
                Err(e) => defmt::debug!("GPS UART: {}", e),
            }
        }
        let rest = self
            .staged
            .get(self.handed..self.staged_len)
            .unwrap_or_default();
        let n = rest.len().min(buf.len());
        buf.get_mut(..n)
            .unwrap_or_default()
            .copy_from_slice(rest.get(..n).unwrap_or_default());
        self.handed += n;
        n
    }

    fn pending(&self) -> usize {
        self.staged_len - self.handed
    }
}

impl GpsLink for GpsAdapter {
    fn set_baud(&mut self, baud: u32) {
        // What was staged came at the old baud.
        self.staged_len = 0;
        self.handed = 0;
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
