//! The card's SPI device holds chip select low from the start of a card
//! operation to its end (embedded-sdmmc makes each byte its own
//! transaction), wakes the card with chip select high, acts as an ordinary
//! device outside operations, and fails every transfer once an operation
//! outlasts its budget.

mod sd_support;

use std::cell::Cell;

use embedded_hal::spi::SpiDevice;
use embedded_hal_mock::eh1::digital::{Mock as PinMock, State};
use embedded_hal_mock::eh1::spi::{Mock, Transaction};
use sd_support::*;
use wobble_core::drivers::sd_spi::{Error, OperationSpi, CARD_OPERATION_BUDGET_US};

fn still() -> u64 {
    0
}

#[test]
fn chip_select_stays_low_across_an_operation() {
    let mut bus = Mock::new(&operation(
        [byte(0xFF, NOTHING), send(17, 5), byte(0xFF, R1_READY)].concat(),
    ));
    let mut pin = PinMock::new(&cs(&OPERATION_CS));
    let mut spi = OperationSpi::new(bus.clone(), pin.clone(), still);
    spi.begin().expect("select");
    let mut r1 = [0u8];
    spi.transfer(&mut [0u8], &[0xFF]).expect("poll");
    spi.write(&command_frame(17, 5)).expect("command");
    spi.transfer(&mut r1, &[0xFF]).expect("response");
    spi.end().expect("deselect");
    assert_eq!(r1, [R1_READY]);
    bus.done();
    pin.done();
}

#[test]
fn wake_up_clocks_go_out_with_chip_select_high() {
    let mut bus = Mock::new(&wake_up_clocks());
    let mut pin = PinMock::new(&cs(&[State::High]));
    let mut spi = OperationSpi::new(bus.clone(), pin.clone(), still);
    spi.wake_up().expect("wake-up");
    bus.done();
    pin.done();
}

#[test]
fn outside_an_operation_each_transaction_has_its_own_select() {
    let mut bus = Mock::new(&[
        Transaction::write_vec(vec![1, 2]),
        Transaction::flush(),
        Transaction::write_vec(vec![3]),
        Transaction::flush(),
    ]);
    let mut pin = PinMock::new(&cs(&[State::Low, State::High, State::Low, State::High]));
    let mut spi = OperationSpi::new(bus.clone(), pin.clone(), still);
    spi.write(&[1, 2]).expect("first");
    spi.write(&[3]).expect("second");
    bus.done();
    pin.done();
}

thread_local! {
    static NOW_US: Cell<u64> = const { Cell::new(0) };
}

/// A clock that moves 1 ms each time it is read (once per transaction).
fn ticking() -> u64 {
    NOW_US.with(|t| {
        t.set(t.get() + 1_000);
        t.get()
    })
}

#[test]
fn an_operation_past_its_budget_fails_at_its_next_byte() {
    let polls = (CARD_OPERATION_BUDGET_US / 1_000) as usize;
    let mut bus = Mock::new(&operation(silence(polls)));
    let mut pin = PinMock::new(&cs(&OPERATION_CS));
    let mut spi = OperationSpi::new(bus.clone(), pin.clone(), ticking);
    spi.begin().expect("select");
    let mut answer = [0u8];
    for _ in 0..polls {
        spi.transfer(&mut answer, &[0xFF]).expect("within budget");
    }
    assert_eq!(spi.transfer(&mut answer, &[0xFF]), Err(Error::Overtime));
    spi.end().expect("deselect");
    bus.done();
    pin.done();
}
