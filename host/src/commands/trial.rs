//! `pada trial`: one trial of a plan, as one array task of a Slurm job
//! array (`SLURM_ARRAY_TASK_ID`), one Kubernetes indexed job
//! (`JOB_COMPLETION_INDEX`), or by hand (`--index`).

use crate::console::{errln, outln};
use crate::error::{usage, CliError};
use crate::plan::execute::{run_index, Outcome};
use crate::plan::store;
use std::path::PathBuf;

/// `pada trial`.
#[derive(Debug, Clone, clap::Args)]
pub struct TrialArgs {
    /// The plan's directory (written by `pada run ... --plan DIR` or
    /// `pada paper ... --plan DIR`).
    #[arg(long, value_name = "DIR")]
    pub plan: PathBuf,
    /// The trial's index in the plan (default: SLURM_ARRAY_TASK_ID, else
    /// JOB_COMPLETION_INDEX).
    #[arg(long, value_name = "N")]
    pub index: Option<u32>,
    /// Added to the index taken from the environment (a plan larger than
    /// the cluster's MaxArraySize is submitted as several arrays).
    #[arg(long, value_name = "K", default_value_t = 0)]
    pub index_offset: u32,
}

/// The environment variables that carry an array task's index, in the
/// order they are looked at.
pub const INDEX_VARIABLES: [&str; 2] = ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"];

/// The trial index: `--index`, else the first index variable that is set
/// (plus the offset); checked against the plan's `trials`.
pub fn resolve_index(
    index: Option<u32>,
    offset: u32,
    env: impl Fn(&str) -> Option<String>,
    trials: usize,
) -> Result<u32, CliError> {
    let valid = format!(
        "valid is 0..={} (the plan has {trials} trials)",
        trials.saturating_sub(1)
    );
    let (i, from) = match index {
        Some(i) => (i as u64, "--index".to_string()),
        None => {
            let Some((var, text)) = INDEX_VARIABLES.iter().find_map(|v| env(v).map(|t| (*v, t)))
            else {
                return Err(usage(format!(
                    "no trial index: give --index N, or run as a Slurm array task (SLURM_ARRAY_TASK_ID) or a Kubernetes indexed job (JOB_COMPLETION_INDEX); {valid}"
                )));
            };
            let i: u64 = text
                .trim()
                .parse()
                .map_err(|_| usage(format!("{var} is {text:?}, not a trial index: {valid}")))?;
            (
                i + offset as u64,
                format!("{var} + --index-offset {offset}"),
            )
        }
    };
    if i >= trials as u64 {
        return Err(usage(format!(
            "trial index {i} (from {from}) is out of range: {valid}"
        )));
    }
    Ok(i as u32)
}

/// Runs `pada trial`.
pub fn run(args: TrialArgs) -> Result<(), CliError> {
    let plan = store::load_header(&args.plan)?;
    let index = resolve_index(
        args.index,
        args.index_offset,
        |v| std::env::var(v).ok(),
        plan.len(),
    )?;
    store::check_trial(&args.plan, &plan, index)?;
    let spec = &plan.trials[index as usize];
    match run_index(&args.plan, &plan, index)? {
        Outcome::AlreadyDone(path) => {
            outln!(
                "trial {}: already done ({} verifies); not run again",
                spec.describe(),
                path.display()
            )?;
        }
        Outcome::Ran {
            path,
            result,
            timing,
            replaced,
        } => {
            if let Some(why) = replaced {
                errln!(
                    "trial {}: replaced a result that did not verify ({why})",
                    spec.describe()
                );
            }
            outln!(
                "trial {}: end performance {:.1}, rise time {:.0} s, MTBF {:.0} s; {:.2} s wall on {}; wrote {}",
                spec.describe(),
                result.end_performance,
                result.rise_time_s,
                result.mtbf_s,
                timing.wall_s,
                timing.host,
                path.display()
            )?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env<'a>(vars: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<String> + 'a {
        move |name| {
            vars.iter()
                .find(|(k, _)| *k == name)
                .map(|(_, v)| v.to_string())
        }
    }

    #[test]
    fn the_index_comes_from_the_flag_or_the_environment() {
        assert_eq!(
            resolve_index(Some(3), 0, env(&[("SLURM_ARRAY_TASK_ID", "1")]), 5).unwrap(),
            3
        );
        assert_eq!(
            resolve_index(None, 0, env(&[("SLURM_ARRAY_TASK_ID", "1")]), 5).unwrap(),
            1
        );
        assert_eq!(
            resolve_index(None, 0, env(&[("JOB_COMPLETION_INDEX", "4")]), 5).unwrap(),
            4
        );
        assert_eq!(
            resolve_index(
                None,
                1000,
                env(&[("SLURM_ARRAY_TASK_ID", "2"), ("JOB_COMPLETION_INDEX", "0")]),
                1005
            )
            .unwrap(),
            1002
        );
    }

    #[test]
    fn a_bad_index_names_its_source_and_the_range() {
        let e = resolve_index(None, 0, env(&[]), 5).unwrap_err().to_string();
        assert!(
            e.contains("SLURM_ARRAY_TASK_ID") && e.contains("valid is 0..=4"),
            "{e}"
        );
        let e = resolve_index(None, 0, env(&[("SLURM_ARRAY_TASK_ID", "x")]), 5)
            .unwrap_err()
            .to_string();
        assert!(e.contains("SLURM_ARRAY_TASK_ID is \"x\""), "{e}");
        let e = resolve_index(None, 0, env(&[("JOB_COMPLETION_INDEX", "-1")]), 5)
            .unwrap_err()
            .to_string();
        assert!(e.contains("not a trial index"), "{e}");
        let e = resolve_index(Some(5), 0, env(&[]), 5)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("trial index 5 (from --index) is out of range: valid is 0..=4"),
            "{e}"
        );
    }
}
