//! The experiment runner of Section VI: trials of learning with periodic
//! greedy test runs, their end performance, rise time and predicted MTBF,
//! and means with 95% confidence intervals across trials run in parallel.
//!
//! Generic over [`task::Task`], so every task (the pendulums, LEO) runs
//! through the same code:
//!
//! | module | what |
//! |---|---|
//! | [`task`] | what the runner needs from a task: its description and plants |
//! | [`tasks`] | the tasks the command line knows, by name |
//! | [`algo`] | the six algorithms of Section V by their command-line names |
//! | [`config`] | what a run is: algorithm, parameter, trials, seed ([`RunConfig`]) |
//! | [`agent_setup`] | the host's agent for a task and a policy |
//! | [`governed`] | the wear governor in a trial (`--mtbf-budget`) |
//! | [`trial`] | one trial: learning with periodic greedy test runs |
//! | [`runner`] | trials and configurations in parallel |
//! | [`metrics`] | end performance and rise time (Section VI) |

pub mod agent_setup;
pub mod algo;
pub mod config;
pub mod governed;
pub mod measured;
pub mod metrics;
pub mod runner;
pub mod table;
pub use pada_sim::task;
pub mod tasks;
pub mod trial;

pub use agent_setup::{build_agent, HostAgent, TILINGS, TRACE};
pub use metrics::{end_performance, rise_time};
pub use config::RunConfig;
pub use runner::{run_configs, run_configs_keeping, run_trials, run_trials_observed, FinishedTrial};
pub use trial::{
    run_trial, run_trial_from, run_trial_keep, StartWith, TestBooks, TestPoint, TrialObserver, TrialResult,
    TrialStart,
};
