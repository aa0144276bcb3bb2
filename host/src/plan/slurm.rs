//! Slurm's client commands as pada uses them: `sbatch` (one job array per
//! submission), `squeue` (what is still pending or running), `sacct` (why
//! a task ended, where accounting is enabled) and `scontrol` (the
//! cluster's MaxArraySize). Also the checks of `--partition` and `--time`.

use crate::error::{usage, CliError};
use anyhow::{bail, Context};
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

/// The state of one array task, as squeue or sacct name it (`PENDING`,
/// `RUNNING`, `CANCELLED`, `FAILED`, …).
pub type TaskStates = BTreeMap<(String, u32), String>;

/// Checks that sbatch can be run.
pub fn check_available() -> Result<(), CliError> {
    match Command::new("sbatch").arg("--version").output() {
        Ok(o) if o.status.success() => Ok(()),
        Ok(o) => Err(usage(format!(
            "--slurm: `sbatch --version` failed ({}): is this a Slurm cluster's login node?",
            String::from_utf8_lossy(&o.stderr).trim()
        ))),
        Err(e) => Err(usage(format!(
            "--slurm needs Slurm's client commands (sbatch, squeue) on PATH: cannot run sbatch ({e})"
        ))),
    }
}

/// The cluster's MaxArraySize (array indices must be below it); Slurm's
/// default 1001 when scontrol does not say.
pub fn max_array_size() -> u32 {
    let Ok(o) = Command::new("scontrol").args(["show", "config"]).output() else {
        return 1001;
    };
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .find_map(|l| {
            let (k, v) = l.split_once('=')?;
            (k.trim() == "MaxArraySize").then(|| v.trim().parse().ok())?
        })
        .filter(|&n| n >= 1)
        .unwrap_or(1001)
}

/// Sorted indices as an array spec: `0-3,7,9-10`.
pub fn array_spec(indices: &[u32]) -> String {
    let mut parts = Vec::new();
    let mut i = 0;
    while i < indices.len() {
        let mut j = i;
        while j + 1 < indices.len() && indices[j + 1] == indices[j] + 1 {
            j += 1;
        }
        parts.push(if j > i {
            format!("{}-{}", indices[i], indices[j])
        } else {
            indices[i].to_string()
        });
        i = j + 1;
    }
    parts.join(",")
}

/// One sbatch submission.
pub struct Submission<'a> {
    /// The job script.
    pub script: &'a Path,
    /// The script's argument (added to each task's index).
    pub offset: u32,
    /// Array indices (relative to `offset`), sorted.
    pub indices: &'a [u32],
    /// At most this many tasks at once (`%K`).
    pub max_parallel: Option<u32>,
    /// Job name.
    pub name: &'a str,
    /// Log file pattern.
    pub output: &'a Path,
    /// `--partition`.
    pub partition: Option<&'a str>,
    /// `--time`.
    pub time: Option<&'a str>,
    /// Start only after this job has ended.
    pub after: Option<&'a str>,
    /// Further sbatch arguments, after pada's own (so they override them).
    pub extra: &'a [String],
}

/// Submits one job array; returns its job id.
pub fn submit(s: &Submission) -> anyhow::Result<String> {
    let mut array = array_spec(s.indices);
    if let Some(k) = s.max_parallel {
        array += &format!("%{k}");
    }
    let mut cmd = Command::new("sbatch");
    cmd.arg("--parsable")
        .arg(format!("--job-name={}", s.name))
        .arg(format!("--array={array}"))
        .arg("--ntasks=1")
        .arg("--cpus-per-task=1")
        .arg(format!("--output={}", s.output.display()));
    if let Some(p) = s.partition {
        cmd.arg(format!("--partition={p}"));
    }
    if let Some(t) = s.time {
        cmd.arg(format!("--time={t}"));
    }
    if let Some(j) = s.after {
        cmd.arg(format!("--dependency=afterany:{j}"));
    }
    cmd.args(s.extra).arg(s.script).arg(s.offset.to_string());
    let out = cmd.output().context("cannot run sbatch")?;
    if !out.status.success() {
        bail!(
            "sbatch refused the job array: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    // --parsable prints `jobid` or `jobid;cluster`.
    let text = String::from_utf8_lossy(&out.stdout);
    let id = text.trim().split(';').next().unwrap_or("").to_string();
    if id.is_empty() || !id.bytes().all(|b| b.is_ascii_digit()) {
        bail!("sbatch printed no job id: {:?}", text.trim());
    }
    Ok(id)
}

/// Parses `JOB_TASK` into its job id and task index.
fn parse_task(id: &str) -> Option<(String, u32)> {
    let (job, task) = id.split_once('_')?;
    Some((job.to_string(), task.parse().ok()?))
}

/// The array tasks of `jobs` still in the queue (pending, running,
/// completing) and their states. An empty queue is an empty map.
pub fn queue(jobs: &[String]) -> anyhow::Result<TaskStates> {
    if jobs.is_empty() {
        return Ok(TaskStates::new());
    }
    let out = Command::new("squeue")
        .args(["--noheader", "--array", "--format=%i|%T"])
        .arg(format!("--jobs={}", jobs.join(",")))
        .output()
        .context("cannot run squeue")?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        // Jobs purged from the controller (MinJobAge after they ended) are
        // "invalid": none of them is queued any more.
        if stderr.contains("Invalid job id") {
            return Ok(TaskStates::new());
        }
        bail!("squeue failed: {}", stderr.trim());
    }
    Ok(String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| {
            let (id, state) = l.trim().split_once('|')?;
            Some((parse_task(id)?, state.to_string()))
        })
        .collect())
}

/// How the array tasks of `jobs` ended, from sacct; `None` where the
/// cluster keeps no accounting (sacct then says it is disabled).
pub fn ended_states(jobs: &[String]) -> Option<TaskStates> {
    if jobs.is_empty() {
        return Some(TaskStates::new());
    }
    let out = Command::new("sacct")
        .args([
            "--noheader",
            "--parsable2",
            "--allocations",
            "--format=JobID,State",
        ])
        .arg(format!("--jobs={}", jobs.join(",")))
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    let text = String::from_utf8_lossy(&out.stdout);
    if text.contains("accounting storage is disabled") {
        return None;
    }
    Some(
        text.lines()
            .filter_map(|l| {
                let (id, state) = l.trim().split_once('|')?;
                Some((parse_task(id)?, state.to_string()))
            })
            .collect(),
    )
}

/// Checks a `--time` limit in one of sbatch's forms: `M`, `M:S`, `H:M:S`,
/// `D-H`, `D-H:M`, `D-H:M:S`.
pub fn check_time(t: &str) -> Result<(), CliError> {
    let bad = || {
        usage(format!(
            "--time {t:?} is not a Slurm time limit: valid forms are MINUTES, MINUTES:SECONDS, HOURS:MINUTES:SECONDS, DAYS-HOURS, DAYS-HOURS:MINUTES, DAYS-HOURS:MINUTES:SECONDS (e.g. 30, 2:00:00, 1-12)"
        ))
    };
    let numbers = |s: &str| {
        s.split(':')
            .map(|p| (!p.is_empty() && p.bytes().all(|b| b.is_ascii_digit())).then_some(()))
            .collect::<Option<Vec<()>>>()
            .map(|v| v.len())
    };
    let fields = match t.split_once('-') {
        Some((days, rest)) => {
            if numbers(days) != Some(1) {
                return Err(bad());
            }
            numbers(rest).filter(|&n| n <= 3)
        }
        None => numbers(t).filter(|&n| n <= 3),
    };
    fields.map(|_| ()).ok_or_else(bad)
}

/// Checks a `--partition` name (or comma-separated list of names).
pub fn check_partition(p: &str) -> Result<(), CliError> {
    let ok = !p.is_empty()
        && p.split(',').all(|n| {
            !n.is_empty()
                && n.bytes()
                    .all(|b| b.is_ascii_alphanumeric() || b"_-.".contains(&b))
        });
    if ok {
        Ok(())
    } else {
        Err(usage(format!(
            "--partition {p:?} is not a partition name: valid is letters, digits, '_', '-', '.', or a comma-separated list of such names"
        )))
    }
}

/// Checks a `--sbatch-arg`: any sbatch option but the ones pada sets for
/// the array itself.
pub fn check_sbatch_arg(a: &str) -> Result<(), CliError> {
    for own in ["--array", "-a", "--parsable", "--wrap"] {
        if a == own || a.starts_with(&format!("{own}=")) || (own == "-a" && a.starts_with("-a")) {
            return Err(usage(format!(
                "--sbatch-arg {a:?}: pada sets {own} itself (the trials to run; use --max-parallel to limit how many run at once)"
            )));
        }
    }
    if a.is_empty() {
        return Err(usage(
            "--sbatch-arg is empty: give an sbatch option such as --mem=2G",
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn array_specs_compress_runs() {
        assert_eq!(array_spec(&[0, 1, 2, 3, 7, 9, 10]), "0-3,7,9-10");
        assert_eq!(array_spec(&[5]), "5");
        assert_eq!(array_spec(&[]), "");
    }

    #[test]
    fn time_limits() {
        for ok in [
            "30",
            "30:00",
            "2:00:00",
            "1-12",
            "1-12:30",
            "1-12:30:05",
            "0",
        ] {
            assert!(check_time(ok).is_ok(), "{ok}");
        }
        for bad in ["", "1h", "1:2:3:4", "-5", "1-", "a-1", "1-2-3", "1:", "1 2"] {
            let e = check_time(bad).unwrap_err().to_string();
            assert!(e.contains("valid forms are"), "{bad}: {e}");
        }
    }

    #[test]
    fn partitions_and_sbatch_args() {
        assert!(check_partition("debug").is_ok());
        assert!(check_partition("cpu,gpu-a100").is_ok());
        assert!(check_partition("a b").is_err());
        assert!(check_partition("").is_err());
        assert!(check_sbatch_arg("--mem=2G").is_ok());
        assert!(check_sbatch_arg("--account=rl").is_ok());
        let e = check_sbatch_arg("--array=0-3").unwrap_err().to_string();
        assert!(e.contains("--max-parallel"), "{e}");
        assert!(check_sbatch_arg("-a0-3").is_err());
        assert!(check_sbatch_arg("--account=x").is_ok());
    }

    #[test]
    fn task_ids() {
        assert_eq!(parse_task("123_4"), Some(("123".into(), 4)));
        assert_eq!(parse_task("123_[4-7]"), None);
        assert_eq!(parse_task("123"), None);
    }
}
