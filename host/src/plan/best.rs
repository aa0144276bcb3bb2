//! The best learner of a plan whose report draws it (`pada paper leo`
//! saves the best trial's weights and gait), kept across array tasks that
//! never talk to each other.
//!
//! Every trial with a finite end performance writes its weights to
//! `DIR/best/NNNNNN.weights` (atomically) after its result, then lists the
//! directory and deletes every file whose trial is worse than the best it
//! sees ("better": higher end performance, ties to the lower index, the
//! local run's rule). Of any two trials, the one that lists last sees both
//! files, so once every trial has finished only the best one's file is
//! left, without locks, on any file system with atomic renames. The merge
//! loads it; if it is missing (a task killed between its result and its
//! weights), the merge runs the best trial again instead.

use super::result::{self, ResultState};
use super::spec::Plan;
use std::path::{Path, PathBuf};

/// The directory of kept learners.
pub fn best_dir(dir: &Path) -> PathBuf {
    dir.join("best")
}

/// Trial `index`'s weights file.
pub fn weights_path(dir: &Path, index: u32) -> PathBuf {
    best_dir(dir).join(format!("{index:06}.weights"))
}

/// Whether `(e, index)` beats `(b, b_index)`.
fn better(e: f64, index: u32, b: f64, b_index: u32) -> bool {
    e > b || (e == b && index < b_index)
}

/// Offers trial `index` (end performance `end`) as the best learner:
/// `save` writes its weights to the path it is given, then worse files are
/// deleted. A trial with a non-finite end performance is never the best.
pub fn offer(
    dir: &Path,
    plan: &Plan,
    index: u32,
    end: f64,
    save: impl FnOnce(&Path) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    if !end.is_finite() {
        return Ok(());
    }
    std::fs::create_dir_all(best_dir(dir))?;
    save(&weights_path(dir, index))?;
    prune(dir, plan);
    Ok(())
}

/// Deletes every kept file worse than the best kept one. Files whose
/// trial has no verified result are left alone (the merge ignores them).
fn prune(dir: &Path, plan: &Plan) {
    let Ok(entries) = std::fs::read_dir(best_dir(dir)) else {
        return;
    };
    let kept: Vec<(u32, f64)> = entries
        .flatten()
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            let index: u32 = name.strip_suffix(".weights")?.parse().ok()?;
            if index as usize >= plan.len() {
                return None;
            }
            match result::read(dir, plan, index) {
                ResultState::Verified(r) => Some((index, r.result.end_performance)),
                _ => None,
            }
        })
        .collect();
    let Some(&(bi, be)) = kept.iter().filter(|(_, e)| e.is_finite()).reduce(|a, b| {
        if better(b.1, b.0, a.1, a.0) {
            b
        } else {
            a
        }
    }) else {
        return;
    };
    for &(i, e) in &kept {
        if i != bi && !better(e, i, be, bi) {
            // Another trial may have deleted it already.
            let _ = std::fs::remove_file(weights_path(dir, i));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::tasks::TaskName;
    use crate::experiment::{RunConfig, TrialResult};
    use crate::plan::result::TrialTiming;
    use crate::plan::{Experiment, ExperimentKind};
    use pada_core::policy::PolicyKind;

    #[test]
    fn only_the_best_file_is_left_whatever_the_order() {
        let plan = Plan::new(Experiment::new(
            ExperimentKind::PaperLeo,
            "pada paper leo".into(),
            &[(
                TaskName::Leo,
                RunConfig {
                    policy: PolicyKind::Sarsa,
                    switch_at_s: None,
                    mtbf_budget_s: None,
                    seconds: 60.0,
                    trials: 5,
                    seed: 1,
                },
            )],
        ))
        .unwrap();
        // Trials 1 and 3 tie for the best; 1 wins (lower index). Trial 4
        // has no finite end performance.
        let ends = [10.0, 50.0, -3.0, 50.0, f64::NAN];
        for order in [[0, 1, 2, 3, 4], [4, 3, 2, 1, 0], [2, 3, 0, 4, 1]] {
            let root = tempfile::tempdir().unwrap();
            for &i in &order {
                let spec = &plan.trials[i];
                let r = TrialResult {
                    trial: spec.trial,
                    seed: spec.trial_seed,
                    end_performance: ends[i],
                    rise_time_s: 0.0,
                    mtbf_s: 1.0,
                    window_reengagements: 0,
                    physical_mtbf_s: 2.0,
                    run_mtbf_s: 2.5,
                    joint_mtbf_s: Vec::new(),
                    physical_joint_mtbf_s: Vec::new(),
                    governor: None,
                    physical_window_reengagements: 0,
                    learning_steps: 0,
                    test_steps: 0,
                    learning_falls: 0,
                    learning_episodes: 0,
                    test_falls: 0,
                    end_walked_m: None,
                    end_speed_m_s: None,
                    saturations: 0,
                    trace_drops: 0,
                    table: None,
                    curve: vec![],
                };
                let t = TrialTiming {
                    started_unix_s: 0.0,
                    wall_s: 0.0,
                    host: "h".into(),
                    slurm_task: None,
                };
                result::write(root.path(), &plan, spec, &r, &t).unwrap();
                offer(root.path(), &plan, i as u32, ends[i], |p| {
                    std::fs::write(p, b"w").map_err(Into::into)
                })
                .unwrap();
            }
            let left: Vec<String> = std::fs::read_dir(best_dir(root.path()))
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect();
            assert_eq!(left, ["000001.weights"], "order {order:?}");
        }
    }
}
