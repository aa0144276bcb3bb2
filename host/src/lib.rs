//! pada on the host: the experiment runner of Section VI, the paper's
//! experiments (Sections VII and VIII), plots, the fatigue check of a
//! recorded torque log, telemetry capture, the software-in-the-loop run,
//! learning on a real robot from the PC (`pada drive`), virtual servos on
//! a pseudo-terminal (`pada servos`) and the `pada` command. The simulator (the pendulums, LEO in rapier3d,
//! the rigs) is the crate `pada_sim`, re-exported here under its module
//! names.

#![warn(missing_docs)]

pub mod board;
/// Telemetry decoding and its CSV: the crate `pada_telemetry`, here under
/// the module name the commands use.
pub use pada_telemetry::capture;
pub mod checkpoint_keeper;
pub mod cli;
pub mod commands;
pub mod display;
pub mod drive;
pub mod error;
pub mod experiment;
/// Foxglove's live WebSocket channels: the crate `pada_telemetry`'s.
pub use pada_telemetry::foxglove;
pub mod gait;
pub mod mcap;
pub mod motion;
pub mod output;
pub mod paper;
pub mod plan;
pub mod plot;
pub mod progress;
pub mod robot_arg;
pub mod robots;
pub mod seed;
pub mod serial_link;
/// The virtual servos (`pada servos`) and the emulated board's bus
/// (`pada sil`): the crate `pada_servos`.
pub use pada_servos as servos;
pub mod sil;
pub mod start_weights;
pub mod stats;
pub mod console;
pub mod summary;
pub mod telemetry;
pub mod timing;
pub mod torque_log;
pub mod watch;
pub mod weights;

pub use pada_sim::{integrator, leo, model_presets, pendulum, rig};
