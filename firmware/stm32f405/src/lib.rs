//! The STM32F405RG board's pieces, shared by the logger binary
//! (`src/main.rs`) and the on-target tests (`hil-tests/on-target`): the pin
//! map, the clock tree, the adapters that plug peripherals into the core's
//! ports, main's assembly of them into the tasks' parts, the start-up
//! register work and the watchdog.
#![no_std]
#![warn(missing_docs)]

pub mod adapters;
pub mod assembly;
pub mod ccm;
pub mod clocks;
pub mod pins;
pub mod power;
pub mod selftest;
pub mod startup;
pub mod watchdog;
