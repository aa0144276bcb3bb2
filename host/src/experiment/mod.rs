//! The experiment runner of Section VI: trials of learning with periodic
//! greedy test runs, their end performance, rise time and predicted MTBF,
//! and means with 95% confidence intervals across trials run in parallel.
//!
//! Generic over [`crate::task::Task`], so every task (the pendulums now,
//! LEO later) runs through the same code.

pub mod agent_setup;
pub mod metrics;
pub mod runner;
pub mod trial;

pub use agent_setup::{build_agent, HostAgent, TILINGS, TRACE};
pub use metrics::{end_performance, rise_time};
pub use runner::{run_configs, run_configs_keeping, run_trials, run_trials_observed, FinishedTrial, RunConfig};
pub use trial::{
    run_trial, run_trial_keep, run_trial_observed, TestPoint, TrialObserver, TrialResult,
};
