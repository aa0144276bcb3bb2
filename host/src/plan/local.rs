//! Running an experiment's configurations in this process: consecutive
//! configurations of one task share one pool of jobs
//! ([`run_configs`]), as the paper commands always ran them.

use super::experiment::Experiment;
use crate::experiment::task::Task;
use crate::experiment::tasks::{visit_task, TaskVisitor};
use crate::experiment::{run_configs, RunConfig, TrialResult};

struct RunGroup<'a> {
    cfgs: &'a [RunConfig],
    progress: &'a (dyn Fn(u64) + Sync),
}

impl TaskVisitor for RunGroup<'_> {
    type Output = anyhow::Result<Vec<Vec<TrialResult>>>;

    fn visit<T: Task>(self, task: &T) -> Self::Output {
        run_configs(task, self.cfgs, self.progress)
    }
}

/// Every configuration's trials, per configuration in trial order.
pub fn run_experiment(
    experiment: &Experiment,
    progress: &(dyn Fn(u64) + Sync),
) -> anyhow::Result<Vec<Vec<TrialResult>>> {
    let configs = &experiment.configurations;
    let mut out = Vec::with_capacity(configs.len());
    let mut start = 0;
    while start < configs.len() {
        let task = configs[start].task_name()?;
        let mut end = start + 1;
        while end < configs.len() && configs[end].task_name()? == task {
            end += 1;
        }
        let cfgs = configs[start..end]
            .iter()
            .map(|c| c.run_config())
            .collect::<anyhow::Result<Vec<_>>>()?;
        out.extend(visit_task(
            task,
            RunGroup {
                cfgs: &cfgs,
                progress,
            },
        )?);
        start = end;
    }
    Ok(out)
}
