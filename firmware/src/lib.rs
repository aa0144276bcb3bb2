//! pada firmware, the part above the registers.
//!
//! Everything the firmware decides lives here, in plain `no_std` Rust that
//! touches no peripheral, so that the host runs its tests
//! (`cargo xtask firmware-test`) and the emulated board of issue 6 runs the
//! very same code. The binary (`src/main.rs`, `src/board/`) only moves bytes
//! and reads counters:
//!
//! | module | what |
//! |---|---|
//! | [`config`] | the robots (physical pendulum at 33 or 20 Hz, LEO at 30 Hz): servos, state, actions, learning parameters, table size, soft limits, configuration hash |
//! | [`io`] | the traits a board implements: servo-bus port, byte streams, sensors, cycle counter |
//! | [`bus`] | Dynamixel Protocol 1.0 transactions with bounded timeouts and retries (codec from `pada_core::dynamixel`) |
//! | [`servo`] | joint calibration, commanded voltage → Moving Speed ratio, torque estimate for the fatigue counter |
//! | [`encoder`] | quadrature counts → unwrapped angle |
//! | [`filter`] | GRL's first-order Butterworth rate filter |
//! | [`pendulum`], [`leo`] | per robot: observation, reward, episode end, PD holds, command mapping |
//! | [`control`] | one control period: safety, agent step, episodes, fatigue, telemetry records |
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
pub mod filter;
pub mod io;
pub mod leo;
pub mod pendulum;
pub mod servo;
pub mod sil;
pub mod timing;
