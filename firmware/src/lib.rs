//! pada firmware, the part above the registers.
//!
//! Everything the firmware decides lives here, in plain `no_std` Rust that
//! touches no peripheral, so that the host runs its tests
//! (`cargo xtask firmware-test`) and the emulated board (QEMU) runs the
//! very same code. The binary (`src/main.rs`, `src/board/`) only moves bytes
//! and reads counters:
//!
//! | module | what |
//! |---|---|
//! | [`config`] | the robots' hardware (servo IDs and calibration, soft limits, encoder) and the learner's fixed sizes; what they learn is `pada_core::robot`, how much they remember `pada_core::profile` |
//! | [`robot`] | the one interface between the controller and a robot ([`robot::RobotAdapter`]) |
//! | [`io`] | the traits a board implements: servo-bus port, byte streams, sensors, cycle counter |
//! | [`bus`] | Dynamixel Protocol 1.0 transactions with bounded timeouts and retries (codec from `pada_core::dynamixel`) |
//! | [`servo`] | joint calibration, commanded voltage → Moving Speed ratio |
//! | [`encoder`] | quadrature counts → unwrapped angle |
//! | [`pendulum`], [`leo`] | per robot: the adapter from counts to the robot's definition, and the wait between episodes |
//! | [`control`] | one control period: safety, the shared episode cycle, fatigue, the wear governor, telemetry records |
//! | [`timing`] | loop-time and overrun accounting |
//! | [`sil`] | software in the loop: the emulated board's lock-step clock and sensor device, shared with the host |
#![cfg_attr(not(test), no_std)]
#![deny(missing_docs)]
#![allow(async_fn_in_trait)]
#![allow(clippy::needless_range_loop)]

pub mod bus;
pub mod config;
pub mod control;
pub mod encoder;
pub mod io;
pub mod leo;
pub mod pendulum;
pub mod robot;
pub mod servo;
pub mod sil;
pub mod timing;
