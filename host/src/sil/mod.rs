//! Software in the loop: the real firmware image learns inside QEMU
//! against the simulated plant (`pada sil`, docs/sil.md).
//!
//! ```text
//!  qemu-system-arm -machine netduinoplus2 -icount shift=0
//!  ┌──────────────────────────────────────┐
//!  │ pada-firmware (feature qemu)         │ USART1 ─ bus.sock ────── BusEmulator ── Rig (pendulum model)
//!  │ the real control loop, agent, safety │ USART2 ─ telemetry.sock ─ Recorder (CSV), commands
//!  │ board: lock-step clock               │ FIFOs  ─ clock ────────── the lock-step loop (run.rs)
//!  └──────────────────────────────────────┘
//! ```
//!
//! - [`bus`]: RX-28 servos and the sensor device on the emulated Dynamixel
//!   bus, with `--fault` injection ([`fault`]);
//! - the robot behind the bus: a [`crate::rig::Rig`] (the physical
//!   pendulum's model, or a LEO stand-in);
//! - [`qemu`]: starting QEMU and connecting its channels;
//! - [`run`]: the lock-step loop, the run's commands, the summary;
//! - [`replay`]: the bit-for-bit replay through the host build of the
//!   firmware's agent;
//! - [`twin`]: the host-only run to compare with: the firmware's controller
//!   on the host against the same model.
//!
//! The board side is `firmware/src/board/qemu.rs`; the protocol between
//! them is `pada_firmware::sil`.

pub mod bus;
pub mod fault;
pub mod qemu;
pub mod replay;
pub mod run;
pub mod twin;
pub mod wall;

pub use run::{run, SilConfig, SilSummary, SilTask};
