//! Experiments as plans of independent trials, so that a
//! cluster runs them: one trial per Slurm array task (or Kubernetes indexed
//! job, or GNU parallel job), results written atomically with checksums,
//! and a merge that reports exactly what the local run reports.
//!
//! | module | what |
//! |---|---|
//! | [`experiment`] | an experiment as data: configurations of task, algorithm, parameter, switch, time, seed |
//! | [`spec`] | the plan: every trial with its configuration, seed and output, and the plan's hash |
//! | [`store`] | the plan's directory: `plan.json`, `trials/`, the sbatch script; loading checks the hash |
//! | [`execute`] | one trial of a plan (`pada trial`) |
//! | [`result`] | a trial's result file: checksummed, exact, written atomically |
//! | [`collect`] | every result of a plan for a merge, or the list of missing and corrupt ones |
//! | [`local`] | an experiment's configurations run in this process |
//! | [`slurm`] | Slurm's client commands (sbatch, squeue, sacct, scontrol) |
//! | [`slurm_run`] | `--slurm`: submit, wait, resubmit, collect |
//! | [`best`] | the best learner of a plan, kept across array tasks without locks |
//! | [`exact`] | floats stored bit for bit in JSON |
//! | [`mode`] | where a command's trials come from: local, plan, merge or Slurm |

pub mod best;
pub mod collect;
pub mod exact;
pub mod execute;
pub mod experiment;
pub mod local;
pub mod mode;
pub mod result;
pub mod slurm;
pub mod slurm_run;
pub mod spec;
pub mod store;

pub use experiment::{Configuration, Experiment, ExperimentKind};
pub use spec::{Plan, TrialSpec};
