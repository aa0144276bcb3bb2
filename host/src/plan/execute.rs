//! Running one trial of a plan (`pada trial`): the trial the index names,
//! with the experiment runner's own [`run_trial_keep`], its result written
//! atomically under `DIR/results/` (and, for a report that draws the best
//! learner, its weights offered to [`best`]). A trial whose result already verifies
//! is not run again, so a resubmitted or repeated array task costs nothing.

use super::best;
use super::result::{self, ResultState, TrialTiming};
use super::spec::{Plan, TrialSpec};
use crate::experiment::task::{Task, TaskSpec};
use crate::experiment::tasks::{visit_task, TaskVisitor};
use crate::experiment::{run_trial_keep, HostAgent, RunConfig, TrialResult};
use std::path::{Path, PathBuf};
use std::time::{Instant, SystemTime, UNIX_EPOCH};

/// What [`run_index`] did.
#[derive(Debug)]
pub enum Outcome {
    /// The trial already had a verified result; nothing ran.
    AlreadyDone(PathBuf),
    /// The trial ran and its result was written.
    Ran {
        /// The result file.
        path: PathBuf,
        /// The result.
        result: Box<TrialResult>,
        /// Its timing.
        timing: TrialTiming,
        /// Why an existing file was replaced (it did not verify), if one was.
        replaced: Option<String>,
    },
}

struct RunOne<'a> {
    cfg: &'a RunConfig,
    trial: u32,
}

/// A trial's result, and its learner with what saving it needs.
type Learned = (TrialResult, HostAgent, bool, TaskSpec);

impl TaskVisitor for RunOne<'_> {
    type Output = anyhow::Result<Learned>;

    fn visit<T: Task>(self, task: &T) -> Self::Output {
        let (result, agent, switched) = run_trial_keep(task, self.cfg, self.trial, &|_| {})?;
        Ok((result, agent, switched, task.spec().clone()))
    }
}

/// Runs trial `index` of `plan` (in `dir`) unless its result verifies.
pub fn run_index(dir: &Path, plan: &Plan, index: u32) -> anyhow::Result<Outcome> {
    let spec = &plan.trials[index as usize];
    let replaced = match result::read(dir, plan, index) {
        ResultState::Verified(_) => {
            return Ok(Outcome::AlreadyDone(result::result_path(dir, plan, index)))
        }
        ResultState::Missing => None,
        ResultState::Corrupt(why) => Some(why),
    };
    result::remove_partials(dir, plan, index);
    let ((result, agent, switched, task_spec), timing) = run_spec(spec)?;
    let path = result::write(dir, plan, spec, &result, &timing)?;
    if plan.experiment.kind.keeps_best_learner() {
        let policy = spec.configuration.run_config()?.policy;
        best::offer(dir, plan, index, result.end_performance, |p| {
            crate::weights::save(p, &task_spec, policy, switched, &agent)
        })?;
    }
    Ok(Outcome::Ran {
        path,
        result: Box::new(result),
        timing,
        replaced,
    })
}

/// Runs the trial `spec` describes and times it.
fn run_spec(spec: &TrialSpec) -> anyhow::Result<(Learned, TrialTiming)> {
    let task = spec.configuration.task_name()?;
    let cfg = spec.configuration.run_config()?;
    let started = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0);
    let clock = Instant::now();
    let learned = visit_task(
        task,
        RunOne {
            cfg: &cfg,
            trial: spec.trial,
        },
    )?;
    let wall_s = clock.elapsed().as_secs_f64();
    anyhow::ensure!(
        learned.0.seed == spec.trial_seed,
        "trial {} ran with seed {} but the plan says {}",
        spec.describe(),
        learned.0.seed,
        spec.trial_seed
    );
    Ok((
        learned,
        TrialTiming {
            started_unix_s: started,
            wall_s,
            host: host_name(),
            slurm_task: slurm_task(),
        },
    ))
}

/// This machine's name (uname's nodename).
pub fn host_name() -> String {
    rustix::system::uname()
        .nodename()
        .to_string_lossy()
        .into_owned()
}

/// `JOB_TASK` of the Slurm array task this process runs in, if any.
fn slurm_task() -> Option<String> {
    let job = std::env::var("SLURM_ARRAY_JOB_ID").ok()?;
    let task = std::env::var("SLURM_ARRAY_TASK_ID").ok()?;
    Some(format!("{job}_{task}"))
}
