//! The board's one pin map: every pin, peripheral, DMA stream and interrupt
//! the firmware uses, named for its role. Nothing else in the crate names a
//! pin. The README's "Board" section shows the same map as a table, and
//! `firmware/docs/board.md` gives the reasons.
//!
//! DMA streams follow RM0090's request mapping (tables 42/43): SPI1 RX on
//! DMA2 stream 2 and TX on stream 3 (channel 3), ADC1 on DMA2 stream 4
//! (channel 0), USART2 RX on DMA1 stream 5 and TX on stream 6 (channel 4).

use embassy_stm32::peripherals::{
    ADC1, DMA1_CH5, DMA1_CH6, DMA2_CH2, DMA2_CH3, DMA2_CH4, IWDG, PA0, PA1, PA2, PA3, PA4, PA5,
    PA6, PA7, PB0, PB1, PB12, PB13, PB14, PB15, PB9, PC0, PC4, SPI1, SPI2, TIM5, USART2,
};
use embassy_stm32::{bind_interrupts, dma, usart, Peri, Peripherals};

bind_interrupts!(
    /// Interrupt handlers of the drivers in use.
    pub struct Irqs {
        DMA2_STREAM2 => dma::InterruptHandler<DMA2_CH2>;
        DMA2_STREAM3 => dma::InterruptHandler<DMA2_CH3>;
        DMA2_STREAM4 => dma::InterruptHandler<DMA2_CH4>;
        DMA1_STREAM5 => dma::InterruptHandler<DMA1_CH5>;
        DMA1_STREAM6 => dma::InterruptHandler<DMA1_CH6>;
        USART2 => usart::InterruptHandler<USART2>;
    }
);

/// ICM-42688-P on SPI1 (mode 0, up to 24 MHz).
pub struct ImuPins {
    /// The SPI peripheral.
    pub spi: Peri<'static, SPI1>,
    /// PA5: SCK.
    pub sck: Peri<'static, PA5>,
    /// PA7: MOSI (sensor SDI).
    pub mosi: Peri<'static, PA7>,
    /// PA6: MISO (sensor SDO).
    pub miso: Peri<'static, PA6>,
    /// PA4: chip select, active low (GPIO).
    pub cs: Peri<'static, PA4>,
    /// DMA2 stream 3: transmit.
    pub tx_dma: Peri<'static, DMA2_CH3>,
    /// DMA2 stream 2: receive.
    pub rx_dma: Peri<'static, DMA2_CH2>,
}

/// microSD socket on SPI2 (blocking: embedded-sdmmc is).
pub struct CardPins {
    /// The SPI peripheral.
    pub spi: Peri<'static, SPI2>,
    /// PB13: SCK.
    pub sck: Peri<'static, PB13>,
    /// PB15: MOSI (card CMD/DI).
    pub mosi: Peri<'static, PB15>,
    /// PB14: MISO (card DAT0/DO), pulled up.
    pub miso: Peri<'static, PB14>,
    /// PB12: chip select (card DAT3/CS), active low (GPIO).
    pub cs: Peri<'static, PB12>,
}

/// Steering potentiometer wiper on the ADC.
pub struct SteeringPins {
    /// The ADC.
    pub adc: Peri<'static, ADC1>,
    /// PC0: ADC123_IN10, the wiper (ends at 3.3 V and GND).
    pub wiper: Peri<'static, PC0>,
    /// DMA2 stream 4: the oversampling ring buffer.
    pub dma: Peri<'static, DMA2_CH4>,
}

/// Hall sensor of the wheel and the IMU's data-ready line on a 32-bit
/// timer's input captures.
pub struct WheelPins {
    /// TIM5, 32-bit, counting at 1 MHz.
    pub timer: Peri<'static, TIM5>,
    /// PA0: TIM5_CH1, the sensor's open-collector output (pulled up; the
    /// timer's own interrupt handler reads it, see `adapters::wheel`).
    pub hall: Peri<'static, PA0>,
    /// PA1: TIM5_CH2, the IMU's INT1 (push-pull, a 100 µs pulse per
    /// sample): the same timer latches each data-ready time.
    pub imu_int1: Peri<'static, PA1>,
}

/// GPS receiver on USART2.
pub struct GpsPins {
    /// The UART.
    pub uart: Peri<'static, USART2>,
    /// PA2: USART2_TX, to the receiver's RX.
    pub tx: Peri<'static, PA2>,
    /// PA3: USART2_RX, from the receiver's TX.
    pub rx: Peri<'static, PA3>,
    /// DMA1 stream 6: transmit (set-up commands).
    pub tx_dma: Peri<'static, DMA1_CH6>,
    /// DMA1 stream 5: the receive ring buffer.
    pub rx_dma: Peri<'static, DMA1_CH5>,
}

/// What the rider hears, sees and presses.
pub struct RiderPins {
    /// PB0: buzzer driver transistor (active buzzer), high = on.
    pub buzzer: Peri<'static, PB0>,
    /// PB1: alert LED (red), high = on.
    pub alert_led: Peri<'static, PB1>,
    /// PB9: status LED (green), high = on.
    pub status_led: Peri<'static, PB9>,
    /// PC4: marker button to GND, internal pull-up.
    pub marker: Peri<'static, PC4>,
}

/// Everything the firmware uses, by role.
pub struct Board {
    /// IMU.
    pub imu: ImuPins,
    /// SD card.
    pub card: CardPins,
    /// Steering sensor.
    pub steering: SteeringPins,
    /// Wheel sensor.
    pub wheel: WheelPins,
    /// GPS.
    pub gps: GpsPins,
    /// Rider I/O.
    pub rider: RiderPins,
    /// Independent watchdog.
    pub watchdog: Peri<'static, IWDG>,
}

impl Board {
    /// Hands out the peripherals by role.
    pub fn new(p: Peripherals) -> Self {
        Self {
            imu: ImuPins {
                spi: p.SPI1,
                sck: p.PA5,
                mosi: p.PA7,
                miso: p.PA6,
                cs: p.PA4,
                tx_dma: p.DMA2_CH3,
                rx_dma: p.DMA2_CH2,
            },
            card: CardPins {
                spi: p.SPI2,
                sck: p.PB13,
                mosi: p.PB15,
                miso: p.PB14,
                cs: p.PB12,
            },
            steering: SteeringPins {
                adc: p.ADC1,
                wiper: p.PC0,
                dma: p.DMA2_CH4,
            },
            wheel: WheelPins {
                timer: p.TIM5,
                hall: p.PA0,
                imu_int1: p.PA1,
            },
            gps: GpsPins {
                uart: p.USART2,
                tx: p.PA2,
                rx: p.PA3,
                tx_dma: p.DMA1_CH6,
                rx_dma: p.DMA1_CH5,
            },
            rider: RiderPins {
                buzzer: p.PB0,
                alert_led: p.PB1,
                status_led: p.PB9,
                marker: p.PC4,
            },
            watchdog: p.IWDG,
        }
    }
}
