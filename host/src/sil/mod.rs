//! Software in the loop: the real firmware image learns inside QEMU
//! against the simulated plant (`pada sil`, docs/sil.md).
//!
//! ```text
//!  qemu-system-arm -machine netduinoplus2 | mps2-an386 -icount shift=0
//!  ┌──────────────────────────────────────┐
//!  │ pada-firmware (feature qemu | mps2)  │  one semihosting channel (two FIFOs):
//!  │ the real control loop, agent, safety │   servo-bus bytes ── BusEmulator ── Rig (pendulum model, rapier3d LEO)
//!  │ board: lock-step clock, forecasts    │   telemetry bytes ── Recorder (CSV), operator, run protocol
//!  └──────────────────────────────────────┘   clock ──────────── the lock-step loop (session.rs)
//! ```
//!
//! - [`bus`]: the emulated board's bus, the crate `pada_servos`'s
//!   `board_bus` (RX-28s on Protocol 1.0, X-series servos on 2.0, Feetech
//!   STS3215s and the sensor device: `pada servos`' virtual servos at a
//!   1 Mbps bus's times), with `--fault` injection ([`fault`]);
//! - the robot behind the bus: a [`crate::rig::Rig`] (the physical
//!   pendulum's model, or the rapier3d LEO with its operator);
//! - [`qemu`]: starting QEMU and its channel (and cutting its power);
//! - [`power_cut`]: `--power-cut` and `--fault hang`: the plan, and what
//!   each reboot found;
//! - [`session`]: the lock-step loop; [`forecast`]: the answers it sends
//!   ahead, so a period's bus traffic takes one exchange;
//! - [`run`]: what to run and setting it up;
//! - [`report`]: the summary and its checks, with the comparison to the
//!   same controller on the host (`crate::board`);
//! - [`replay`]: the bit-for-bit replay through the host build of the
//!   firmware's agent;
//! - [`wall`]: where the wall-clock time goes.
//!
//! The board side is `firmware/src/board/lockstep/`; the protocol between
//! them is `pada_firmware::sil`.

pub mod check;
pub mod config;
pub mod forecast;
pub mod power_cut;
pub mod qemu;
pub mod replay;
pub mod report;
pub mod run;
pub mod session;
pub mod wall;

/// The emulated board's bus and its faults: `pada_servos`'s, which
/// `pada servos` shares.
pub use pada_servos::{board_bus as bus, fault};
pub use report::{SilSummary, LEARNING_CHECK_S, WALKING_CHECK_S};
pub use config::{machine, SilConfig, SilTask};
pub use run::run;
