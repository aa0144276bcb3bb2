//! Where the trials of `pada run` and `pada paper` come from: this process
//! (the default), a plan written for others to run (`--plan DIR`), the
//! results of such a plan (`--merge DIR`), or Slurm job arrays that this
//! process submits and waits for (`--slurm`).

use super::collect::{self, Collected};
use super::slurm::{check_partition, check_sbatch_arg, check_time};
use super::slurm_run::{self, SlurmOptions};
use super::spec::Plan;
use super::store::{self, Written};
use crate::console::{errln, outln};
use crate::error::CliError;
use crate::timing::RunTiming;
use std::path::{Path, PathBuf};

/// The cluster options of `pada run` and `pada paper`.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct ClusterOptions {
    /// Write the experiment as a plan of independent trials to DIR (one
    /// JSON file per trial, and an sbatch script) instead of running it;
    /// with --slurm, the plan directory to use (default: OUT/plan).
    #[arg(long, value_name = "DIR")]
    pub plan: Option<PathBuf>,
    /// Merge the results of the plan in DIR (written by `pada trial`) into
    /// the same report as a local run; give the options the plan was
    /// written with.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["plan", "slurm"])]
    pub merge: Option<PathBuf>,
    /// Run the trials as a Slurm job array (one trial per array task),
    /// wait for them, submit failed ones again, and merge.
    #[arg(long)]
    pub slurm: bool,
    /// Slurm partition for the array tasks.
    #[arg(long, value_name = "P", requires = "slurm")]
    pub partition: Option<String>,
    /// At most K array tasks at once.
    #[arg(long, value_name = "K", requires = "slurm", value_parser = clap::value_parser!(u32).range(1..=100000))]
    pub max_parallel: Option<u32>,
    /// Time limit per array task (sbatch --time: MINUTES, H:M:S, D-H, ...).
    #[arg(long, value_name = "T", requires = "slurm")]
    pub time: Option<String>,
    /// A further sbatch option, e.g. --sbatch-arg=--mem=2G (repeatable).
    #[arg(
        long = "sbatch-arg",
        value_name = "ARG",
        requires = "slurm",
        allow_hyphen_values = true
    )]
    pub sbatch_args: Vec<String>,
    /// How many times a trial left without a result (cancelled, failed,
    /// timed out) is submitted again.
    #[arg(long, value_name = "N", requires = "slurm", default_value_t = 2, value_parser = clap::value_parser!(u32).range(0..=20))]
    pub retries: u32,
}

/// Where the trials come from.
#[derive(Debug, Clone, PartialEq)]
pub enum Mode {
    /// Run them in this process.
    Local,
    /// Write the plan to this directory and stop.
    WritePlan(PathBuf),
    /// Merge the results of the plan in this directory.
    Merge(PathBuf),
    /// Run the plan in this directory on Slurm.
    Slurm(PathBuf, SlurmOptions),
}

impl Mode {
    /// The plan's directory, for the modes that use one.
    pub fn plan_dir(&self) -> Option<&Path> {
        match self {
            Mode::Local => None,
            Mode::WritePlan(d) | Mode::Merge(d) | Mode::Slurm(d, _) => Some(d),
        }
    }
}

impl ClusterOptions {
    /// The mode the options ask for, checked; `out` is the output directory
    /// (a `--slurm` plan goes to `out/plan` unless `--plan` names one).
    pub fn mode(&self, out: &Path) -> Result<Mode, CliError> {
        if let Some(dir) = &self.merge {
            return Ok(Mode::Merge(dir.clone()));
        }
        if self.slurm {
            if let Some(p) = &self.partition {
                check_partition(p)?;
            }
            if let Some(t) = &self.time {
                check_time(t)?;
            }
            for a in &self.sbatch_args {
                check_sbatch_arg(a)?;
            }
            let dir = self
                .plan
                .clone()
                .unwrap_or_else(|| slurm_run::default_plan_dir(out));
            return Ok(Mode::Slurm(
                dir,
                SlurmOptions {
                    partition: self.partition.clone(),
                    max_parallel: self.max_parallel,
                    time: self.time.clone(),
                    sbatch_args: self.sbatch_args.clone(),
                    retries: self.retries,
                },
            ));
        }
        Ok(match &self.plan {
            Some(dir) => Mode::WritePlan(dir.clone()),
            None => Mode::Local,
        })
    }
}

/// What a plan mode gave.
pub enum FromPlan {
    /// The plan was written; nothing to report.
    Written,
    /// Every trial's result, and how long the run took.
    Results {
        /// The results.
        collected: Collected,
        /// The run's timing.
        timing: Box<RunTiming>,
    },
}

/// Writes, merges or runs `plan` as `mode` says (not [`Mode::Local`]).
/// Writing prints the next steps on stdout (as JSON with `json`).
pub fn from_plan(mode: &Mode, plan: &Plan, json: bool) -> Result<FromPlan, CliError> {
    let labels: Vec<String> = plan
        .experiment
        .configurations
        .iter()
        .map(|c| c.label.clone())
        .collect();
    match mode {
        Mode::Local => Err(CliError::Runtime(anyhow::anyhow!(
            "internal: a local run has no plan"
        ))),
        Mode::WritePlan(dir) => {
            let written = store::write(dir, plan)?;
            print_next_steps(dir, plan, written, json)?;
            Ok(FromPlan::Written)
        }
        Mode::Merge(dir) => {
            store::load_matching(dir, plan)?;
            let collected = collect::collect(dir, plan).map_err(|incomplete| {
                for p in &incomplete.problems {
                    errln!("merge: {p}");
                }
                CliError::Runtime(anyhow::Error::new(incomplete).context("no report written"))
            })?;
            let timing = RunTiming::of_trials(
                "merge",
                None,
                env_steps(&collected),
                &collected.timings,
                &labels,
            );
            Ok(FromPlan::Results {
                collected,
                timing: Box::new(timing),
            })
        }
        Mode::Slurm(dir, opts) => {
            let outcome = slurm_run::run(dir, plan, opts)?;
            let mut timing = RunTiming::of_trials(
                "slurm",
                Some(outcome.wall_s),
                env_steps(&outcome.collected),
                &outcome.collected.timings,
                &labels,
            );
            timing.slurm = Some(outcome.report);
            Ok(FromPlan::Results {
                collected: outcome.collected,
                timing: Box::new(timing),
            })
        }
    }
}

fn env_steps(c: &Collected) -> u64 {
    c.per_config
        .iter()
        .flatten()
        .map(|r| r.learning_steps + r.test_steps)
        .sum()
}

fn print_next_steps(dir: &Path, plan: &Plan, written: Written, json: bool) -> Result<(), CliError> {
    let command = &plan.experiment.command;
    let last = plan.len().saturating_sub(1);
    if json {
        outln!(
            "{}",
            serde_json::json!({
                "plan": dir,
                "hash": plan.hash,
                "trials": plan.len(),
                "command": command,
                "already_written": written == Written::Existing,
                "sbatch": format!("sbatch {}", store::array_script(dir).display()),
                "trial": format!("pada trial --plan {} --index N", dir.display()),
                "merge": format!("{command} --merge {}", dir.display()),
            })
        )?;
        return Ok(());
    }
    let what = match written {
        Written::New => "wrote",
        Written::Existing => "found (already written, results kept)",
    };
    outln!(
        "{what} the plan of `{command}`: {} trials, hash {}, in {}",
        plan.len(),
        plan.short_hash(),
        dir.display()
    )?;
    outln!(
        "run every trial:  sbatch {}   (one trial per array task, indices 0-{last})",
        store::array_script(dir).display()
    )?;
    outln!(
        "  or one by one:  pada trial --plan {} --index N   (N = 0..{last}; or SLURM_ARRAY_TASK_ID / JOB_COMPLETION_INDEX)",
        dir.display()
    )?;
    outln!("then merge:       {command} --merge {}", dir.display())
}

/// An experiment's trials, however they were obtained.
pub enum Trials {
    /// Only the plan was written (`--plan DIR`): nothing to report.
    PlanWritten,
    /// Every configuration's results, in trial order, and the run's timing.
    Results(Vec<Vec<crate::experiment::TrialResult>>, RunTiming),
}

/// The trials of `experiment` as `mode` says: `local` runs them in this
/// process (timed here); the other modes go through the experiment's plan.
pub fn obtain(
    mode: &Mode,
    experiment: &super::Experiment,
    json: bool,
    local: impl FnOnce() -> anyhow::Result<Vec<Vec<crate::experiment::TrialResult>>>,
) -> Result<Trials, CliError> {
    if *mode == Mode::Local {
        let start = std::time::Instant::now();
        let results = local()?;
        let wall_s = start.elapsed().as_secs_f64();
        let steps = results
            .iter()
            .flatten()
            .map(|r| r.learning_steps + r.test_steps)
            .sum();
        return Ok(Trials::Results(results, RunTiming::local(wall_s, steps)));
    }
    let plan = Plan::new(experiment.clone()).map_err(CliError::Runtime)?;
    Ok(match from_plan(mode, &plan, json)? {
        FromPlan::Written => Trials::PlanWritten,
        FromPlan::Results { collected, timing } => Trials::Results(collected.per_config, *timing),
    })
}

/// [`obtain`] for a paper experiment: while its trials run in this
/// process, a progress bar over its `expected_steps` environment steps,
/// labelled `label`. `None` when only the plan was written.
pub fn obtain_with_bar(
    mode: &Mode,
    experiment: &super::Experiment,
    expected_steps: u64,
    label: &str,
    run: impl FnOnce(&(dyn Fn(u64) + Sync)) -> anyhow::Result<Vec<Vec<crate::experiment::TrialResult>>>,
) -> Result<Option<(Vec<Vec<crate::experiment::TrialResult>>, RunTiming)>, CliError> {
    let trials = obtain(mode, experiment, false, || {
        let bar = crate::progress::steps_bar(expected_steps, label);
        let results = run(&|n| bar.inc(n));
        bar.finish_and_clear();
        results
    })?;
    Ok(match trials {
        Trials::PlanWritten => None,
        Trials::Results(r, t) => Some((r, t)),
    })
}
