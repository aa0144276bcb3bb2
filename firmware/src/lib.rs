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
//! | [`config`] | the learner's fixed sizes; what a robot is (its task, joints, servos, calibration, soft limits, encoder) is its one definition in `pada_core::robot`, how much it remembers `pada_core::profile` |
//! | [`io`] | the traits a board implements: servo-bus port, byte streams, sensors, cycle counter |
//! | [`bus`] | Dynamixel transactions in each servo's protocol (1.0 and 2.0) with bounded timeouts and retries, one robot's period on the bus, its bus time (codecs from `pada_core::dynamixel`) |
//! | [`sensor_device`] | the encoder and foot switches as a device on the servo bus (emulated boards, a PC), and the operator's call |
//! | [`encoder`] | quadrature counts → unwrapped angle |
//! | [`control`] | one control period, generic over the robot's rules (`pada_core::robot::RobotRules`): safety, the shared episode cycle, fatigue, the wear governor, telemetry records |
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
pub mod sensor_device;
pub mod sil;
pub mod timing;
