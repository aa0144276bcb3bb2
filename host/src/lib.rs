//! pada on the host: the plants, the experiment runner of Section VI, the
//! paper's pendulum experiments (Section VII), the LEO biped in rapier3d
//! (Section VIII, [`leo`]), plots and the fatigue check of a recorded
//! torque log.

#![warn(missing_docs)]

pub mod board;
pub mod capture;
pub mod checkpoint_keeper;
pub mod cli;
pub mod commands;
pub mod display;
pub mod error;
pub mod experiment;
pub mod foxglove;
pub mod gearbox_spec;
pub mod integrator;
pub mod leo;
pub mod mcap;
pub mod model_presets;
pub mod output;
pub mod paper;
pub mod pendulum;
pub mod plan;
pub mod plot;
pub mod progress;
pub mod rig;
pub mod robots;
pub mod seed;
pub mod serial_link;
pub mod sil;
pub mod stats;
pub mod console;
pub mod summary;
pub mod telemetry;
pub mod timing;
pub mod torque_log;
pub mod watch;
pub mod weights;
