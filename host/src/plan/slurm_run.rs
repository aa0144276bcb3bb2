//! `--slurm`: a plan run as Slurm job arrays, one trial per array task.
//!
//! 1. The plan is written (or found) in its directory; trials whose results
//!    already verify are skipped, and tasks an earlier run of the same plan
//!    left in the queue are waited for rather than submitted twice.
//! 2. The other trials are submitted as one job array (several when the
//!    plan is larger than the cluster's MaxArraySize).
//! 3. The queue is polled with squeue, with progress on stderr.
//! 4. Trials left without a verified result (cancelled, failed, timed out,
//!    killed) are submitted again, at most `retries` times.
//! 5. The results are collected for the merge.

use super::collect::{self, Collected, Incomplete};
use super::slurm::{self, Submission, TaskStates};
use super::spec::Plan;
use super::store;
use crate::console::errln;
use crate::error::{usage, CliError};
use crate::timing::SlurmReport;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// How to submit.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SlurmOptions {
    /// `--partition`.
    pub partition: Option<String>,
    /// At most this many array tasks at once.
    pub max_parallel: Option<u32>,
    /// `--time` limit per array task.
    pub time: Option<String>,
    /// Further sbatch arguments.
    pub sbatch_args: Vec<String>,
    /// How many times a trial without a verified result is submitted again.
    pub retries: u32,
}

/// A finished `--slurm` run.
pub struct SlurmOutcome {
    /// Every trial's verified result.
    pub collected: Collected,
    /// What was submitted.
    pub report: SlurmReport,
    /// From the first submission to the last result \[s\] (0 when every
    /// trial had verified already).
    pub wall_s: f64,
}

/// How often the queue is polled. A task that ends is seen within this
/// time; Slurm itself starts the next pending task on its next scheduling
/// pass (about every second with the CI cluster's settings).
const POLL: Duration = Duration::from_millis(500);

/// Consecutive failed squeue calls tolerated (a controller restarting)
/// before giving up; the jobs keep running and a re-run finds them.
const SQUEUE_FAILURES: u32 = 120;

/// Runs `plan` in `dir` on Slurm.
pub fn run(dir: &Path, plan: &Plan, opts: &SlurmOptions) -> Result<SlurmOutcome, CliError> {
    slurm::check_available()?;
    // Absolute, so that the array tasks' logs land in the plan whatever
    // directory Slurm starts them in.
    let dir = &std::path::absolute(dir)
        .map_err(|e| usage(format!("cannot resolve {}: {e}", dir.display())))?;
    store::write(dir, plan)?;
    // The script names this pada executable: written again on every run, so
    // a plan written by another build runs with this one.
    store::write_array_script(dir, plan).map_err(|e| {
        usage(format!(
            "cannot write the job script in {}: {e:#}",
            dir.display()
        ))
    })?;
    let jobs_file = store::slurm_dir(dir).join("jobs.txt");
    let mut report = SlurmReport::default();
    let mut first_submission: Option<Instant> = None;

    let earlier = read_jobs(&jobs_file);
    let queued = slurm::queue(&earlier).unwrap_or_default();
    if !queued.is_empty() {
        errln!(
            "slurm: {} tasks of an earlier run of this plan are still queued (jobs {}); waiting for them",
            queued.len(),
            earlier.join(",")
        );
        first_submission = Some(Instant::now());
        wait(dir, plan, &earlier)?;
    }

    let mut scan = collect::scan(dir, plan);
    report.already_done = scan.verified();
    if report.already_done > 0 {
        errln!(
            "slurm: {} of {} trials already have verified results in {}; they are not run again",
            report.already_done,
            plan.len(),
            dir.display()
        );
    }
    let max_array = slurm::max_array_size();
    let mut attempt = 0;
    let mut last_jobs: Vec<Submitted> = Vec::new();
    while !scan.problems.is_empty() && attempt <= opts.retries {
        let todo: Vec<u32> = scan.problems.iter().map(|p| p.index).collect();
        if attempt > 0 {
            let ids: Vec<String> = last_jobs.iter().map(|j| j.id.clone()).collect();
            let states = slurm::ended_states(&ids);
            for p in &scan.problems {
                errln!(
                    "slurm: trial {} left {}; submitting it again (attempt {} of {})",
                    p.trial,
                    why_no_result(&states, &last_jobs, max_array, dir, p.index, &p.what),
                    attempt + 1,
                    opts.retries + 1
                );
            }
            report.resubmitted.extend(&todo);
        }
        first_submission.get_or_insert_with(Instant::now);
        last_jobs = submit_all(dir, plan, &todo, opts, max_array)?;
        let ids: Vec<String> = last_jobs.iter().map(|j| j.id.clone()).collect();
        append_jobs(&jobs_file, &ids)?;
        report.jobs.extend(ids.iter().cloned());
        wait(dir, plan, &ids)?;
        attempt += 1;
        scan = collect::scan(dir, plan);
    }
    let wall_s = first_submission.map_or(0.0, |t| t.elapsed().as_secs_f64());
    if !scan.problems.is_empty() {
        for p in &scan.problems {
            errln!("slurm: {p}");
        }
        return Err(CliError::Runtime(anyhow::Error::new(Incomplete {
            total: plan.len(),
            problems: scan.problems,
        })
        .context(format!(
            "after {} submissions; no report written, a re-run with the same directory submits only these",
            attempt
        ))));
    }
    let results = scan.results.into_iter().flatten().collect();
    Ok(SlurmOutcome {
        collected: collect::from_results(plan, results),
        report,
        wall_s,
    })
}

/// A submitted job array: its id and the plan index of its array index 0.
struct Submitted {
    id: String,
    offset: u32,
}

/// The cause of a missing result: sacct's state where accounting is kept,
/// else the file's problem and the task's log.
fn why_no_result(
    states: &Option<TaskStates>,
    jobs: &[Submitted],
    max_array: u32,
    dir: &Path,
    index: u32,
    what: &str,
) -> String {
    // The array task that ran plan index `index`: (job id, array index).
    let Some((job, task)) = jobs
        .iter()
        .find(|j| (j.offset..j.offset.saturating_add(max_array)).contains(&index))
        .map(|j| (j.id.as_str(), index - j.offset))
    else {
        return format!("no verified result ({what})");
    };
    if let Some(state) = states
        .as_ref()
        .and_then(|s| s.get(&(job.to_string(), task)))
    {
        return format!("no verified result ({state}; {what})");
    }
    let log = Some(store::slurm_dir(dir).join(format!("{job}_{task}.out"))).filter(|p| p.exists());
    match log {
        Some(p) => format!("no verified result ({what}; log {})", p.display()),
        None => format!("no verified result ({what})"),
    }
}

/// Submits `todo` (sorted plan indices) as job arrays of at most
/// `max_array` indices each; with `--max-parallel`, each array starts
/// after the previous one ended, so the limit holds across arrays.
fn submit_all(
    dir: &Path,
    plan: &Plan,
    todo: &[u32],
    opts: &SlurmOptions,
    max_array: u32,
) -> Result<Vec<Submitted>, CliError> {
    let script = store::array_script(dir);
    let output = store::slurm_dir(dir).join("%A_%a.out");
    let name = format!("pada-{}", plan.short_hash());
    let mut jobs: Vec<Submitted> = Vec::new();
    let mut rest = todo;
    while let Some(&first) = rest.first() {
        let offset = first / max_array * max_array;
        let n = rest.iter().take_while(|&&i| i < offset + max_array).count();
        let indices: Vec<u32> = rest[..n].iter().map(|i| i - offset).collect();
        rest = &rest[n..];
        let after = opts.max_parallel.and(jobs.last().map(|j| j.id.as_str()));
        let id = slurm::submit(&Submission {
            script: &script,
            offset,
            indices: &indices,
            max_parallel: opts.max_parallel,
            name: &name,
            output: &output,
            partition: opts.partition.as_deref(),
            time: opts.time.as_deref(),
            after,
            extra: &opts.sbatch_args,
        })
        .map_err(CliError::Runtime)?;
        errln!(
            "slurm: submitted job {id}: {} (indices {}{})",
            trials(indices.len()),
            slurm::array_spec(&indices.iter().map(|i| i + offset).collect::<Vec<_>>()),
            if offset > 0 {
                format!(", array offset {offset}")
            } else {
                String::new()
            }
        );
        jobs.push(Submitted { id, offset });
    }
    Ok(jobs)
}

/// `1 trial`, `6 trials`.
fn trials(n: usize) -> String {
    if n == 1 {
        "1 trial".into()
    } else {
        format!("{n} trials")
    }
}

fn read_jobs(path: &Path) -> Vec<String> {
    std::fs::read_to_string(path)
        .map(|t| t.split_whitespace().map(str::to_string).collect())
        .unwrap_or_default()
}

fn append_jobs(path: &Path, jobs: &[String]) -> Result<(), CliError> {
    let mut all = read_jobs(path);
    all.extend(jobs.iter().cloned());
    crate::output::write_atomic(path, (all.join("\n") + "\n").as_bytes()).map_err(CliError::Runtime)
}

/// Progress: a bar on a terminal, else a line when the counts change (at
/// most every 10 s) so that logs show it too.
struct Progress {
    bar: Option<ProgressBar>,
    last: Option<(usize, usize, usize)>,
    last_line: Option<Instant>,
}

impl Progress {
    fn new(total: usize) -> Progress {
        let bar = std::io::stderr().is_terminal().then(|| {
            let b = ProgressBar::with_draw_target(Some(total as u64), ProgressDrawTarget::stderr());
            b.set_style(
                ProgressStyle::with_template(
                    "slurm [{bar:30}] {pos}/{len} trials, {msg}, {elapsed}",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
            );
            b
        });
        Progress {
            bar,
            last: None,
            last_line: None,
        }
    }

    fn show(&mut self, done: usize, total: usize, running: usize, pending: usize, force: bool) {
        let now = (done, running, pending);
        if let Some(b) = &self.bar {
            b.set_position(done as u64);
            b.set_message(format!("{running} running, {pending} pending"));
            return;
        }
        let due = self
            .last_line
            .is_none_or(|t| t.elapsed() >= Duration::from_secs(10));
        if self.last != Some(now) && (due || force) {
            errln!("slurm: {done}/{total} trials done, {running} running, {pending} pending");
            self.last = Some(now);
            self.last_line = Some(Instant::now());
        }
    }

    fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

/// Waits until no task of `jobs` is queued, showing how many of the
/// plan's results exist.
fn wait(dir: &Path, plan: &Plan, jobs: &[String]) -> Result<(), CliError> {
    let mut progress = Progress::new(plan.len());
    let mut failures = 0;
    loop {
        let queued = match slurm::queue(jobs) {
            Ok(q) => {
                failures = 0;
                q
            }
            Err(e) => {
                failures += 1;
                if failures >= SQUEUE_FAILURES {
                    progress.finish();
                    return Err(CliError::Runtime(e.context(format!(
                        "the queue could not be read for {} s; the jobs ({}) may still run: a re-run with the same plan directory waits for them",
                        (POLL * SQUEUE_FAILURES).as_secs(),
                        jobs.join(",")
                    ))));
                }
                std::thread::sleep(POLL);
                continue;
            }
        };
        let running = queued.values().filter(|s| s.as_str() == "RUNNING").count();
        let pending = queued.len() - running;
        let done = count_result_files(dir, plan);
        progress.show(done, plan.len(), running, pending, queued.is_empty());
        if queued.is_empty() {
            progress.finish();
            return Ok(());
        }
        std::thread::sleep(POLL);
    }
}

/// Result files present (verified later; this is for progress only).
fn count_result_files(dir: &Path, plan: &Plan) -> usize {
    plan.trials
        .iter()
        .filter(|t| dir.join(&t.result).exists())
        .count()
}

/// The default plan directory of a `--slurm` run writing to `out`.
pub fn default_plan_dir(out: &Path) -> PathBuf {
    out.join("plan")
}
