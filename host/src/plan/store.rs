//! A plan on disk, in its own directory:
//!
//! ```text
//! DIR/plan.json             the experiment, its configurations, the hash
//! DIR/trials/NNNNNN.json    one per trial: {"plan": hash, "trial": {...}}
//! DIR/slurm-array.sh        an sbatch script: one trial per array task
//! DIR/results/NNNNNN.json   written by `pada trial` (see super::result)
//! DIR/slurm/                array tasks' logs, and the jobs --slurm submitted
//! ```
//!
//! Every file is written through a temporary file and a rename, and
//! `plan.json` last, so a directory with a `plan.json` holds a whole plan.
//! Loading recomputes the hash from every file and refuses a plan whose
//! files no longer match it.

use super::experiment::{Configuration, Experiment, ExperimentKind};
use super::spec::{Plan, TrialSpec, PADA_VERSION, PLAN_FORMAT};
use crate::error::{usage, CliError};
use crate::output::write_atomic;
use anyhow::Context;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// `plan.json`.
#[derive(Serialize, Deserialize)]
struct PlanFile {
    format: u32,
    pada_version: String,
    kind: ExperimentKind,
    command: String,
    trials: u32,
    hash: String,
    configurations: Vec<Configuration>,
}

/// `trials/NNNNNN.json`.
#[derive(Serialize, Deserialize)]
struct TrialFile {
    plan: String,
    trial: TrialSpec,
}

/// What [`write`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Written {
    /// The plan was written.
    New,
    /// The directory already held this plan (its results are kept).
    Existing,
}

fn plan_json(dir: &Path) -> PathBuf {
    dir.join("plan.json")
}

fn trial_json(dir: &Path, index: u32) -> PathBuf {
    dir.join("trials").join(format!("{index:06}.json"))
}

/// The directory of array tasks' logs.
pub fn slurm_dir(dir: &Path) -> PathBuf {
    dir.join("slurm")
}

/// The sbatch script of a plan.
pub fn array_script(dir: &Path) -> PathBuf {
    dir.join("slurm-array.sh")
}

/// Writes `plan` to `dir`, or finds it already there. A directory that holds
/// another plan, or files but no plan, is refused.
pub fn write(dir: &Path, plan: &Plan) -> Result<Written, CliError> {
    if plan_json(dir).exists() {
        let existing = load(dir)?;
        if existing.hash == plan.hash {
            return Ok(Written::Existing);
        }
        return Err(another_plan(dir, &existing, plan));
    }
    if let Ok(mut entries) = std::fs::read_dir(dir) {
        if entries.next().is_some() {
            return Err(usage(format!(
                "plan directory {} is not empty and holds no plan.json: give a new or empty directory",
                dir.display()
            )));
        }
    }
    write_files(dir, plan)
        .map_err(|e| usage(format!("cannot write the plan to {}: {e:#}", dir.display())))?;
    Ok(Written::New)
}

fn write_files(dir: &Path, plan: &Plan) -> anyhow::Result<()> {
    for sub in ["trials", "results", "slurm"] {
        std::fs::create_dir_all(dir.join(sub))
            .with_context(|| format!("cannot create {}", dir.join(sub).display()))?;
    }
    for t in &plan.trials {
        let file = TrialFile {
            plan: plan.hash.clone(),
            trial: t.clone(),
        };
        write_atomic(
            &trial_json(dir, t.index),
            (serde_json::to_string_pretty(&file)? + "\n").as_bytes(),
        )?;
    }
    write_array_script(dir, plan)?;
    let e = &plan.experiment;
    let file = PlanFile {
        format: PLAN_FORMAT,
        pada_version: PADA_VERSION.to_string(),
        kind: e.kind,
        command: e.command.clone(),
        trials: plan.len() as u32,
        hash: plan.hash.clone(),
        configurations: e.configurations.clone(),
    };
    write_atomic(
        &plan_json(dir),
        (serde_json::to_string_pretty(&file)? + "\n").as_bytes(),
    )
}

/// Writes the plan's sbatch script, naming this pada executable.
pub fn write_array_script(dir: &Path, plan: &Plan) -> anyhow::Result<()> {
    let script = array_script_text(dir, plan)?;
    write_atomic(&array_script(dir), script.as_bytes())?;
    make_executable(&array_script(dir))
}

fn make_executable(path: &Path) -> anyhow::Result<()> {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755))
        .with_context(|| format!("cannot make {} executable", path.display()))
}

/// `'text'` for sh, with any `'` inside closed, escaped and reopened.
pub fn sh_quote(text: &str) -> String {
    format!("'{}'", text.replace('\'', r"'\''"))
}

/// The sbatch script: `sbatch DIR/slurm-array.sh` runs the whole plan. Its
/// optional first argument is added to `SLURM_ARRAY_TASK_ID`, for plans
/// larger than a cluster's MaxArraySize (submitted as several arrays).
fn array_script_text(dir: &Path, plan: &Plan) -> anyhow::Result<String> {
    let exe = std::env::current_exe().context("cannot find the pada executable")?;
    let dir = std::path::absolute(dir).context("cannot make the plan's path absolute")?;
    let logs = slurm_dir(&dir).join("%A_%a.out");
    Ok(format!(
        "#!/bin/sh\n\
         # One trial of the plan of `{command}` per Slurm array task\n\
         # (written by `pada ... --plan`; plan hash {hash}).\n\
         #   sbatch {script}              every trial\n\
         #   sbatch --array=3,7 {script}  only trials 3 and 7\n\
         # pada and the plan directory must be reachable from the compute nodes.\n\
         #SBATCH --job-name=pada-{short}\n\
         #SBATCH --array=0-{last}\n\
         #SBATCH --ntasks=1\n\
         #SBATCH --cpus-per-task=1\n\
         #SBATCH --output={logs}\n\
         exec {exe} trial --plan {dir_q} --index-offset \"${{1:-0}}\"\n",
        command = plan.experiment.command,
        hash = plan.hash,
        script = array_script(&dir).display(),
        short = plan.short_hash(),
        last = plan.len().saturating_sub(1),
        logs = logs.display(),
        exe = sh_quote(&exe.to_string_lossy()),
        dir_q = sh_quote(&dir.to_string_lossy()),
    ))
}

fn another_plan(dir: &Path, existing: &Plan, wanted: &Plan) -> CliError {
    usage(format!(
        "{} holds the plan of `{}` (hash {}), not of `{}` (hash {}): give the options the plan was written with, or another directory",
        dir.display(),
        existing.experiment.command,
        existing.short_hash(),
        wanted.experiment.command,
        wanted.short_hash()
    ))
}

/// Loads the plan in `dir`, checking every file against the hash.
pub fn load(dir: &Path) -> Result<Plan, CliError> {
    let plan = load_header(dir)?;
    for i in 0..plan.len() as u32 {
        check_trial(dir, &plan, i)?;
    }
    Ok(plan)
}

/// Loads `plan.json` and checks it against its hash. The trials follow
/// from its configurations, so they are enumerated again rather than read;
/// [`check_trial`] then compares a trial's file with its enumeration. (A
/// trial checks only its own file: reading all of them in each of N array
/// tasks would cost N² reads.)
pub fn load_header(dir: &Path) -> Result<Plan, CliError> {
    let bad = |why: String| usage(format!("plan {}: {why}", dir.display()));
    let path = plan_json(dir);
    let text = std::fs::read(&path).map_err(|e| {
        bad(format!(
            "cannot read {} ({e}): write a plan with `pada run ... --plan DIR` or `pada paper ... --plan DIR`",
            path.display()
        ))
    })?;
    let file: PlanFile =
        serde_json::from_slice(&text).map_err(|e| bad(format!("plan.json is not a plan ({e})")))?;
    if file.format != PLAN_FORMAT {
        return Err(bad(format!(
            "format {} is not supported: valid is {PLAN_FORMAT}",
            file.format
        )));
    }
    if file.pada_version != PADA_VERSION {
        return Err(bad(format!(
            "written by pada {}, but this is pada {PADA_VERSION}: trials of another version may differ, write the plan again",
            file.pada_version
        )));
    }
    let changed = |what: String| {
        bad(format!(
            "{what}: a file of the plan was changed after it was written"
        ))
    };
    let experiment = Experiment {
        kind: file.kind,
        command: file.command,
        configurations: file.configurations,
    };
    let plan = Plan::new(experiment).map_err(|e| changed(format!("{e:#}")))?;
    if plan.hash != file.hash || plan.len() != file.trials as usize {
        return Err(changed(format!(
            "plan.json hashes to {} but says {}",
            plan.short_hash(),
            file.hash.get(..12).unwrap_or(&file.hash)
        )));
    }
    Ok(plan)
}

/// Checks that trial `index`'s file is the plan's trial.
pub fn check_trial(dir: &Path, plan: &Plan, index: u32) -> Result<(), CliError> {
    let bad = |why: String| usage(format!("plan {}: {why}", dir.display()));
    let path = trial_json(dir, index);
    let text =
        std::fs::read(&path).map_err(|e| bad(format!("cannot read {} ({e})", path.display())))?;
    let t: TrialFile = serde_json::from_slice(&text)
        .map_err(|e| bad(format!("{} is not a trial of a plan ({e})", path.display())))?;
    if t.plan != plan.hash || t.trial != plan.trials[index as usize] {
        return Err(bad(format!(
            "{} is not the plan's trial {index}: a file of the plan was changed after it was written",
            path.display()
        )));
    }
    Ok(())
}

/// Loads the plan in `dir` and checks that it is `wanted` (the plan of the
/// options given on the command line).
pub fn load_matching(dir: &Path, wanted: &Plan) -> Result<Plan, CliError> {
    let existing = load(dir)?;
    if existing.hash != wanted.hash {
        return Err(another_plan(dir, &existing, wanted));
    }
    Ok(existing)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::tasks::TaskName;
    use crate::experiment::RunConfig;
    use pada_core::policy::PolicyKind;

    fn plan(seed: u64) -> Plan {
        Plan::new(Experiment::new(
            ExperimentKind::Run,
            format!("pada run --seed {seed}"),
            &[(
                TaskName::Pendulum,
                RunConfig {
                    policy: PolicyKind::LowPass { alpha: 0.834 },
                    switch_at_s: Some(30.0),
                    mtbf_budget_s: None,
                    seconds: 60.0,
                    trials: 3,
                    seed,
                },
            )],
        ))
        .unwrap()
    }

    #[test]
    fn a_written_plan_loads_back_and_is_found_again() {
        let root = tempfile::tempdir().unwrap();
        let dir = root.path().join("p");
        let p = plan(1);
        assert_eq!(write(&dir, &p).unwrap(), Written::New);
        assert_eq!(load(&dir).unwrap(), p);
        assert_eq!(write(&dir, &p).unwrap(), Written::Existing);
        let e = write(&dir, &plan(2)).unwrap_err().to_string();
        assert!(e.contains("holds the plan of `pada run --seed 1`"), "{e}");
        let script = std::fs::read_to_string(array_script(&dir)).unwrap();
        assert!(script.contains("#SBATCH --array=0-2\n"), "{script}");
        assert!(script.contains("trial --plan '"), "{script}");
    }

    #[test]
    fn an_edited_trial_file_is_refused() {
        let root = tempfile::tempdir().unwrap();
        let dir = root.path().join("p");
        write(&dir, &plan(1)).unwrap();
        let path = trial_json(&dir, 1);
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::write(&path, text.replace("\"seconds\": 60.0", "\"seconds\": 6.0")).unwrap();
        let e = load(&dir).unwrap_err().to_string();
        assert!(e.contains("a file of the plan was changed"), "{e}");
    }

    #[test]
    fn a_full_directory_without_a_plan_is_refused() {
        let root = tempfile::tempdir().unwrap();
        std::fs::write(root.path().join("notes.txt"), "x").unwrap();
        let e = write(root.path(), &plan(1)).unwrap_err().to_string();
        assert!(e.contains("holds no plan.json"), "{e}");
        assert!(load(root.path())
            .unwrap_err()
            .to_string()
            .contains("cannot read"));
    }

    #[test]
    fn quoting_for_sh() {
        assert_eq!(sh_quote("/a b/c"), "'/a b/c'");
        assert_eq!(sh_quote("it's"), r"'it'\''s'");
    }
}
