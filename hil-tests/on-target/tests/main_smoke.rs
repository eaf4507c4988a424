//! A smoke test of the assembled logger: the board brought up and the
//! card, `CONFIG.TXT`, log header, sampler and GPS built by the library's
//! `assembly` exactly as `main.rs` builds them, the sampler on an interrupt
//! executor above the card writer in thread mode, as in `main.rs`. After
//! 5 s of frames the writer closes the log through its own close path; the
//! card is then opened again through a new file system on the same device
//! (`CardLogger::into_device`) and the log is decoded with the core's
//! decoder: a header naming this firmware and board, the configuration in
//! force, and every frame of the run, 10 ms apart, in blocks with no gap.
//!
//! Run: `cargo test -p wobble-on-target --target thumbv7em-none-eabihf
//! --test main_smoke` with a FAT32 card in the socket (it gets a new
//! `RUNnnnnn.WBL`, as a ride would) and the IMU fitted; a GPS receiver is
//! not needed.
#![no_std]
#![no_main]

use defmt_rtt as _;

#[cfg(test)]
#[embedded_test::tests]
mod tests {
    use core::fmt::Write;

    use embassy_executor::InterruptExecutor;
    use embassy_stm32::interrupt;
    use embassy_stm32::interrupt::{InterruptExt, Priority};
    use embassy_time::Instant;
    use embedded_sdmmc::{Mode, VolumeIdx};
    use wobble_core::app::sampler::{self, Sampler};
    use wobble_core::app::{gps, writer};
    use wobble_core::channels::{RecordQueue, SharedStatus};
    use wobble_core::format::{Event, Record, BLOCK_LEN};
    use wobble_core::logger::{self, CardLogger, FixedTime, HeaderSpec, LoggerConfig, LoggerState};
    use wobble_on_target::{decode_file, FrameSpacing};
    use wobble_stm32f405::adapters;
    use wobble_stm32f405::adapters::gps::GpsAdapter;
    use wobble_stm32f405::assembly::{card_and_config, header, sampler_parts, Ports};

    /// 5 s of frames at 100 Hz.
    const FRAMES: u32 = 500;

    static SHARED: SharedStatus = SharedStatus::new();
    static EXECUTOR_HIGH: InterruptExecutor = InterruptExecutor::new();
    static EXECUTOR_MEDIUM: InterruptExecutor = InterruptExecutor::new();

    #[interrupt]
    unsafe fn UART4() {
        // SAFETY: the vector belongs to this executor alone, as in main.
        unsafe { EXECUTOR_HIGH.on_interrupt() }
    }

    #[interrupt]
    unsafe fn UART5() {
        // SAFETY: the vector belongs to this executor alone, as in main.
        unsafe { EXECUTOR_MEDIUM.on_interrupt() }
    }

    /// The sampler for `FRAMES` frames, then the end of the ride.
    #[embassy_executor::task]
    async fn sampler_task(mut sampler: Sampler, mut ports: Ports, queue: &'static RecordQueue) {
        ports.imu.start().await;
        sampler::run(
            &mut sampler,
            &mut ports,
            queue,
            &SHARED,
            FRAMES,
            &mut |_, _| {},
        )
        .await;
        SHARED.request_stop();
    }

    #[embassy_executor::task]
    async fn gps_task(mut port: GpsAdapter, queue: &'static RecordQueue) {
        gps::run_link(&mut port, queue, &SHARED, &mut |_| {}).await;
    }

    /// What the log holds, as the decoder reads it.
    #[derive(Default)]
    struct Log {
        records: u32,
        /// Whether the first record is the log info, and whether it names
        /// this firmware, board, rate and run.
        info: Option<(bool, bool)>,
        channels: u32,
        config_lines: usize,
        config_wrong: u32,
        /// The frames and those not 10 ms after the one before.
        spacing: FrameSpacing,
        dropouts: u32,
        /// Gaps, skipped bytes, bad records, impossible values, time jumps.
        anomalies: u32,
    }

    impl Log {
        fn see(&mut self, event: Event<'_>, spec: &HeaderSpec<'_>, run: u32) {
            let Event::Record(record) = event else {
                self.anomalies += 1;
                return;
            };
            let first = self.records == 0;
            self.records += 1;
            match record {
                Record::LogInfo(info) => {
                    let names_us = info.firmware == spec.firmware
                        && info.device_id == spec.device_id
                        && info.sample_rate_hz == spec.sample_rate_hz
                        && info.run == run;
                    self.info = Some((first, names_us));
                }
                Record::Channel(_) => self.channels += 1,
                Record::Config(line) => {
                    if spec.config.get(self.config_lines) != Some(&line.text) {
                        self.config_wrong += 1;
                    }
                    self.config_lines += 1;
                }
                Record::Frame(frame) => self.spacing.see(frame.t_us),
                Record::Dropout(_) => self.dropouts += 1,
                _ => {}
            }
        }
    }

    #[test]
    #[timeout(60)]
    async fn the_assembled_logger_writes_a_log_that_closes_and_decodes() {
        let (board, _) = wobble_on_target::board();
        // The queue as main has it: in CCM (0x1000_0000-0x1000_FFFF).
        let queue = defmt::unwrap!(wobble_stm32f405::ccm::record_queue());
        let at = core::ptr::from_ref(queue) as usize;
        defmt::assert!(
            (0x1000_0000..0x1001_0000).contains(&at),
            "queue at {=usize:x}",
            at
        );
        let (card, loaded) = card_and_config(board.card);
        let config = loaded.config;
        for fault in loaded.faults.records(Instant::now().as_micros()) {
            queue.push(Record::Fault(fault));
        }
        let spec = header(&config);
        let mut logger = CardLogger::new(card, FixedTime::EPOCH, spec, LoggerConfig::DEFAULT);
        // The writer's first poll, here, to learn the run number it opens.
        logger.poll(Instant::now().as_micros());
        let LoggerState::Logging { run } = logger.state() else {
            defmt::panic!("no log file opened: is a FAT32 card in the socket?");
        };
        let _wheel_timer = adapters::wheel::start(board.wheel);
        let (sampler, ports) = sampler_parts(board.imu, board.steering, board.rider, &config);

        interrupt::UART4.set_priority(Priority::P6);
        let high = EXECUTOR_HIGH.start(interrupt::UART4);
        high.spawn(defmt::unwrap!(sampler_task(sampler, ports, queue)));
        interrupt::UART5.set_priority(Priority::P7);
        let medium = EXECUTOR_MEDIUM.start(interrupt::UART5);
        medium.spawn(defmt::unwrap!(gps_task(GpsAdapter::new(board.gps), queue)));

        // Returns once the sampler has asked it to stop and the log is closed.
        defmt::unwrap!(writer::run(&mut logger, queue, &SHARED).await);
        let stats = logger.stats();
        defmt::info!("run {}: {}", run, stats);
        defmt::assert_eq!(stats.files_opened, 1);
        defmt::assert_eq!(stats.frames_lost, 0);
        defmt::assert_eq!(stats.frames_on_card, FRAMES);
        // The writer counted its card operations: a real card's worst
        // iteration within the queue's sizing.
        let figures = SHARED.writer();
        defmt::info!(
            "writer: {}, queue high water {}",
            figures,
            queue.high_water()
        );
        defmt::assert!(figures.ops_max >= 1);
        defmt::assert!(figures.ops_max <= wobble_core::channels::WRITER_OPS_PER_ITERATION);

        let volumes = logger::volumes(logger.into_device(), FixedTime::EPOCH);
        let volume = defmt::unwrap!(volumes.open_volume(VolumeIdx(0)).ok());
        let root = defmt::unwrap!(volume.open_root_dir().ok());
        let mut name: heapless::String<12> = heapless::String::new();
        defmt::unwrap!(write!(name, "RUN{run:05}.WBL").ok());
        let file = defmt::unwrap!(root.open_file_in_dir(name.as_str(), Mode::ReadOnly).ok());
        defmt::assert_eq!(file.length() % BLOCK_LEN as u32, 0, "whole blocks");

        let mut log = Log::default();
        let decoded = decode_file(&file, |event| log.see(event, &spec, run));
        defmt::info!("{}: {}", name.as_str(), decoded);

        defmt::assert_eq!(
            log.info,
            Some((true, true)),
            "log info first, naming this run"
        );
        defmt::assert!(log.channels > 0, "no channel definitions");
        defmt::assert_eq!(log.config_lines, spec.config.len());
        defmt::assert_eq!(log.config_wrong, 0);
        defmt::assert_eq!(log.spacing.frames, FRAMES);
        defmt::assert_eq!(log.spacing.steps_off, 0);
        defmt::assert_eq!(log.dropouts, 0);
        defmt::assert_eq!(log.anomalies, 0);
        defmt::assert_eq!(decoded.blocks_lost, 0);
        defmt::assert_eq!(decoded.out_of_order_blocks, 0);
        defmt::assert_eq!(decoded.damaged_blocks, 0);
    }
}
