//! pada firmware: the pada-core learner on an STM32F4, driving Dynamixel
//! RX-28 servos, without breaking the robot while it learns.
//!
//! Boot: clocks and pins ([`board`]), the weight table in CCM RAM, the
//! controller for the robot chosen at build time, the checkpoint (weights and
//! learner state) from flash if its configuration matches, a fault if the
//! watchdog reset the chip, then the tasks of [`tasks`]. Logs go out over
//! RTT (defmt), telemetry over USART2 (pada_core::wire frames).
#![no_std]
#![no_main]

mod board;
mod tasks;

use core::mem::MaybeUninit;
use defmt::{info, unwrap};
use embassy_executor::Spawner;
use pada_core::fixed::Q16;
use pada_core::policy::PolicyKind;
use pada_core::wire::{self, ToHost};
use pada_firmware::config::{Robot, WeightTable, DEFAULT_SEED, WEIGHTS};
use pada_firmware::control::Controller;

/// The robot this image drives (cargo features `robot-leo`,
/// `robot-pendulum-20hz`; the 33 Hz pendulum otherwise).
const ROBOT: Robot = if cfg!(feature = "robot-leo") {
    Robot::Leo
} else if cfg!(feature = "robot-pendulum-20hz") {
    Robot::Pendulum20
} else {
    Robot::Pendulum33
};

/// The policy at boot; the host chooses another with `SetPolicy`.
const BOOT_POLICY: PolicyKind = PolicyKind::Sarsa;

/// The weight table: 64 KiB, all of the F405/F407's core-coupled RAM (zero
/// wait states, off the DMA bus). The F446 has no CCM; there it is in SRAM.
/// NOLOAD: the startup code leaves it as it is; [`weight_table`] zeroes it
/// and the controller initialises it.
#[cfg_attr(not(feature = "stm32f446"), link_section = ".ccmram")]
static mut WEIGHT_TABLE: MaybeUninit<WeightTable> = MaybeUninit::uninit();

/// The weight table, once.
fn weight_table() -> &'static mut WeightTable {
    static TAKEN: static_cell::StaticCell<()> = static_cell::StaticCell::new();
    // Panics on a second call, so the `&'static mut` below is unique.
    TAKEN.init(());
    // SAFETY: reached once (above); the table is zeroed before the
    // reference is made, and all-zero bits are valid `Q16`s.
    unsafe {
        let table = &mut *core::ptr::addr_of_mut!(WEIGHT_TABLE);
        table.as_mut_ptr().cast::<Q16>().write_bytes(0, WEIGHTS);
        table.assume_init_mut()
    }
}

// The real boards run embassy's thread-mode executor; the emulated board
// its own, which advances the lock-step clock when nothing is left to run.
#[cfg_attr(not(feature = "qemu"), embassy_executor::main)]
#[cfg_attr(
    feature = "qemu",
    embassy_executor::main(entry = "cortex_m_rt::entry", executor = "crate::board::Executor")
)]
async fn main(spawner: Spawner) {
    let board = board::Board::init();
    info!("pada firmware {}: {}", env!("CARGO_PKG_VERSION"), ROBOT.name());

    let mut ctl = match Controller::new(ROBOT, BOOT_POLICY, weight_table(), DEFAULT_SEED) {
        Ok(ctl) => ctl,
        // The configurations are constants checked by the host tests.
        Err(e) => defmt::panic!("controller configuration: {}", defmt::Debug2Format(&e)),
    };
    info!(
        "table: {=usize} weights ({=usize} bytes) at {=usize:x}; configuration hash {=u32:x}",
        ctl.weights().len(),
        core::mem::size_of_val(ctl.weights()),
        ctl.weights().as_ptr() as usize,
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
