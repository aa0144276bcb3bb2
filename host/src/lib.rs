//! pada on the host: the plants, the experiment runner of Section VI, the
//! paper's pendulum experiments (Section VII), plots and the fatigue check
//! of a recorded torque log.

pub mod algo;
pub mod experiment;
pub mod integrator;
pub mod pendulum;
pub mod seed;
pub mod stats;
pub mod task;
pub mod cli;
pub mod commands;
pub mod error;
pub mod output;
pub mod paper;
pub mod plot;
pub mod progress;
pub mod summary;
pub mod tasks;
pub mod torque_log;
