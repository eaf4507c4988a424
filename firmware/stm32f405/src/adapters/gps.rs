//! The GPS receiver on USART2: a DMA ring buffer for what it sends, and
//! the boot-time set-up commands from the core.

use embassy_stm32::mode::Async;
use embassy_stm32::usart::{RingBufferedUartRx, UartTx};
use embassy_time::Timer;
use wobble_core::app::ports::GpsPort;
use wobble_core::drivers::gnss_setup::{
    baud_commands, rate_commands, Command, BOOT_BAUDS, TARGET_BAUD,
};

/// DMA ring size: 115 200 baud is 11.5 bytes/ms, so 1 KiB holds 89 ms,
/// far more than the GPS task's executor is ever kept from running.
pub const RING_BYTES: usize = 1024;

/// A receiver applying a new baud rate or rate needs a moment before the
/// next command (u-blox: ~100 ms after CFG-PRT).
const SETTLE_MS: u64 = 150;

/// Asks the receiver for 115 200 baud, 20 Hz, RMC and GGA. Leaves the UART
/// at 115 200 baud.
pub async fn configure_receiver(tx: &mut UartTx<'static, Async>) {
    for baud in BOOT_BAUDS {
        send_all(tx, baud, &baud_commands()).await;
    }
    send_all(tx, TARGET_BAUD, &rate_commands()).await;
}

async fn send_all(tx: &mut UartTx<'static, Async>, baud: u32, commands: &[Command]) {
    if tx.set_baudrate(baud).is_err() {
        defmt::warn!("GPS: cannot set {} baud", baud);
        return;
    }
    for cmd in commands {
        if tx.write(cmd).await.is_err() {
            defmt::warn!("GPS: set-up command not sent");
        }
    }
    let _ = tx.flush().await;
    Timer::after_millis(SETTLE_MS).await;
}

/// The receive side as the GPS task's [`GpsPort`].
pub struct GpsAdapter {
    rx: RingBufferedUartRx<'static>,
}

impl GpsAdapter {
    /// Starts the ring buffer.
    pub fn new(mut rx: RingBufferedUartRx<'static>) -> Self {
        rx.start_uart();
        Self { rx }
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
                Err(e) => defmt::warn!("GPS UART: {}", e),
            }
        }
    }
}
