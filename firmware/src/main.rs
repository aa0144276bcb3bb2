//! pada firmware: the pada-core learner on an STM32F4, driving Dynamixel
//! RX-28 servos, without breaking the robot while it learns.
//!
//! Boot: clocks and pins ([`board`]), the weight table where the board's
//! learner profile puts it ([`table`]), the controller for the robot chosen
//! at build time, the checkpoint (weights and
//! learner state) from flash if its configuration matches, a fault if the
//! watchdog reset the chip, then the tasks of [`tasks`]. Logs go out over
//! RTT (defmt), telemetry over USART2 (pada_core::wire frames).
#![no_std]
#![no_main]

mod board;
mod table;
mod tasks;

use defmt::{info, unwrap};
use embassy_executor::Spawner;
use pada_core::policy::PolicyKind;
use pada_core::weights::WeightStore;
use pada_core::wire::{self, ToHost};
use pada_firmware::config::DEFAULT_SEED;
use pada_firmware::robot::RobotAdapter;
use table::{Ctl, ThisRobot, PROFILE};

/// The policy at boot; the host chooses another with `SetPolicy`.
const BOOT_POLICY: PolicyKind = PolicyKind::Sarsa;

// The real boards run embassy's thread-mode executor; the emulated board
// its own, which advances the lock-step clock when nothing is left to run.
#[cfg_attr(not(feature = "qemu"), embassy_executor::main)]
#[cfg_attr(
    feature = "qemu",
    embassy_executor::main(entry = "cortex_m_rt::entry", executor = "crate::board::Executor")
)]
async fn main(spawner: Spawner) {
    let board = board::Board::init();
    info!(
        "pada firmware {}: {} on board profile {}",
        env!("CARGO_PKG_VERSION"),
        ThisRobot::ROBOT.name(),
        PROFILE.board.name()
    );

    let mut ctl: Ctl = match Ctl::new(PROFILE, BOOT_POLICY, table::take(), DEFAULT_SEED) {
        Ok(ctl) => ctl,
        // The profiles are constants checked by the host tests.
        Err(e) => defmt::panic!("controller configuration: {}", defmt::Debug2Format(&e)),
    };
    info!(
        "table: {=usize} weights ({=usize} bytes, {}) in {}; configuration hash {=u32:x}",
        ctl.weights().len(),
        ctl.weights().len() * PROFILE.format.bytes(),
        PROFILE.format,
        PROFILE.memory.name(),
        ctl.config_hash()
    );

    tasks::send_reliable(ToHost::Hello(ctl.hello())).await;
    tasks::boot_checkpoint(&mut ctl, &board.flash).await;
    // After the checkpoint, which may restore another policy or the switch.
    tasks::send_reliable(ToHost::Policy(ctl.policy_report())).await;
    if board.watchdog_reset {
        let t = ctl.watchdog_reset();
        defmt::warn!("reset by the independent watchdog: Fault until the host clears it");
        tasks::send_reliable(ToHost::State(wire::StateChange { step: 0, from: t.from, to: t.to })).await;
        if let Some(cause) = t.entered_fault() {
            tasks::send_reliable(ToHost::Fault(wire::Fault { step: 0, time_ms: 0, cause })).await;
        }
    }

    let joints = ctl.config().joints;
    spawner.spawn(unwrap!(tasks::telemetry_tx(board.telemetry_tx)));
    spawner.spawn(unwrap!(tasks::telemetry_rx(board.telemetry_rx)));
    spawner.spawn(unwrap!(tasks::servo_bus(board.servo_port, joints)));
    spawner.spawn(unwrap!(tasks::watchdog(board.watchdog, board.led)));
    spawner.spawn(unwrap!(tasks::control(tasks::ControlLoop {
        ctl,
        sensors: board.sensors,
        flash: board.flash,
        cycles: board.cycles,
        cpu_hz: board::CPU_HZ,
    })));
}
