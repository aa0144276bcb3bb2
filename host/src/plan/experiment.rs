//! An experiment as data: its kind, the command line that describes it,
//! and its configurations (task, algorithm and parameter, switch, learning
//! time, trials, seed). The local runner, the plan and the merge all start
//! from the same [`Experiment`], so they agree on what trial `i` is.

use crate::experiment::algo::{label, parameter_of, policy_kind_of, Algo, PolicyFlags};
use crate::experiment::tasks::TaskName;
use crate::experiment::RunConfig;
use crate::seed::trial_seed;
use anyhow::{anyhow, bail};
use clap::ValueEnum;
use serde::{Deserialize, Serialize};

/// Which command reports the experiment's results.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ExperimentKind {
    /// `pada run`: one configuration.
    Run,
    /// `pada paper pendulum`: Section VII.
    PaperPendulum,
    /// `pada paper leo`: Section VIII.
    PaperLeo,
    /// `pada paper wear`: every strategy and the wear governor.
    PaperWear,
}

impl ExperimentKind {
    /// Whether its report draws the best trial's learner (so each trial of
    /// its plan offers its weights, [`super::best`]).
    pub fn keeps_best_learner(self) -> bool {
        self == ExperimentKind::PaperLeo
    }

    /// The command that writes, merges and reports it.
    pub fn command(self) -> &'static str {
        match self {
            ExperimentKind::Run => "pada run",
            ExperimentKind::PaperPendulum => "pada paper pendulum",
            ExperimentKind::PaperLeo => "pada paper leo",
            ExperimentKind::PaperWear => "pada paper wear",
        }
    }
}

/// One configuration of an experiment, as data a trial can be run from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Configuration {
    /// Its index in the experiment.
    pub index: u32,
    /// A label for listings: task, algorithm, parameter, switch.
    pub label: String,
    /// The task's command-line name (`pendulum`, `physical-pendulum`, `leo`).
    pub task: String,
    /// The algorithm's command-line name (Section V).
    pub algo: String,
    /// α (Eq. 8) or Δ (Eq. 9), if the algorithm takes one (OU's θ, pink
    /// noise's σ, the penalty's weight for the gentle explorations).
    pub parameter: Option<f32>,
    /// The second parameter, for the algorithms that take two (OU's σ).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub parameter2: Option<f32>,
    /// The wear governor's MTBF budget \[s\], if one runs (`--mtbf-budget`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mtbf_budget_s: Option<f32>,
    /// Learning time of the switch back to SARSA(λ) \[s\] (Section VIII).
    #[serde(with = "super::exact::opt_f64")]
    pub switch_at_s: Option<f64>,
    /// Learning time per trial \[s of simulated time\].
    #[serde(with = "super::exact::f64")]
    pub seconds: f64,
    /// Master seed; trial `t` is seeded with [`trial_seed`]`(seed, t)`.
    pub seed: u64,
    /// Trials of this configuration.
    pub trials: u32,
    /// The board whose learner profile runs the trial, for runners that
    /// take one; absent for the host's own learner.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub board: Option<String>,
}

impl Configuration {
    /// The configuration `index` of `task` running `cfg`.
    pub fn new(index: u32, task: TaskName, cfg: &RunConfig) -> Configuration {
        let switch = cfg
            .switch_at_s
            .map(|s| format!(", switch at {s} s"))
            .unwrap_or_default();
        let budget = cfg
            .mtbf_budget_s
            .map(|b| format!(", MTBF budget {b} s"))
            .unwrap_or_default();
        let algo = crate::experiment::algo::algo_of(&cfg.policy);
        Configuration {
            index,
            label: format!("{task} {}{switch}{budget}", label(&cfg.policy)),
            task: task.to_string(),
            algo: algo.name().to_string(),
            parameter: parameter_of(&cfg.policy),
            parameter2: (algo.parameter_names().len() > 1).then(|| cfg.policy.parameters()[1]),
            mtbf_budget_s: cfg.mtbf_budget_s,
            switch_at_s: cfg.switch_at_s,
            seconds: cfg.seconds,
            seed: cfg.seed,
            trials: cfg.trials,
            board: None,
        }
    }

    /// The task, parsed back from its name.
    pub fn task_name(&self) -> anyhow::Result<TaskName> {
        TaskName::from_str(&self.task, false).map_err(|_| {
            anyhow!(
                "configuration {}: unknown task {:?} (valid: pendulum, physical-pendulum, leo)",
                self.index,
                self.task
            )
        })
    }

    /// The runner's configuration, parsed back and checked.
    pub fn run_config(&self) -> anyhow::Result<RunConfig> {
        let algo = Algo::from_name(&self.algo).ok_or_else(|| {
            anyhow!(
                "configuration {}: unknown algorithm {:?}",
                self.index,
                self.algo
            )
        })?;
        let names = algo.parameter_names();
        let given = [self.parameter, self.parameter2];
        if given.iter().skip(names.len()).any(Option::is_some) {
            match names.len() {
                0 => bail!("configuration {}: {algo} takes no parameter", self.index),
                n => bail!("configuration {}: {algo} takes only {n} parameter(s) ({})", self.index, names.join(", ")),
            }
        }
        let mut flags = PolicyFlags::default();
        for (name, value) in names.iter().zip(given) {
            match *name {
                "alpha" => flags.alpha = value,
                "delta" => flags.delta = value,
                "theta" => flags.theta = value,
                "sigma" => flags.sigma = value,
                _ => flags.weight = value,
            }
        }
        let policy = policy_kind_of(algo, &flags)
            .map_err(|e| anyhow!("configuration {}: {e}", self.index))?;
        if self.board.is_some() {
            bail!(
                "configuration {}: board {:?} given, but this pada runs trials on the host's learner only",
                self.index,
                self.board.as_deref().unwrap_or_default()
            );
        }
        Ok(RunConfig {
            policy,
            switch_at_s: self.switch_at_s,
            mtbf_budget_s: self.mtbf_budget_s,
            seconds: self.seconds,
            trials: self.trials,
            seed: self.seed,
        })
    }
}

/// An experiment: what a plan holds and what a merge reports.
#[derive(Debug, Clone, PartialEq)]
pub struct Experiment {
    /// Which command reports it.
    pub kind: ExperimentKind,
    /// The command line that describes it (in reports, and to tell plans
    /// apart).
    pub command: String,
    /// Its configurations, in report order.
    pub configurations: Vec<Configuration>,
}

/// One trial of an experiment: trial `trial` of configuration `config`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TrialRef {
    /// Index of the configuration.
    pub config: usize,
    /// Trial index within it.
    pub trial: u32,
}

impl Experiment {
    /// An experiment of `kind` from `(task, run configuration)` pairs.
    pub fn new(kind: ExperimentKind, command: String, configs: &[(TaskName, RunConfig)]) -> Self {
        Experiment {
            kind,
            command,
            configurations: configs
                .iter()
                .enumerate()
                .map(|(i, (task, cfg))| Configuration::new(i as u32, *task, cfg))
                .collect(),
        }
    }

    /// Every trial, configuration by configuration and trial by trial: the
    /// order of plan indices (and of the local runner's jobs).
    pub fn trials(&self) -> Vec<TrialRef> {
        self.configurations
            .iter()
            .enumerate()
            .flat_map(|(c, cfg)| (0..cfg.trials).map(move |trial| TrialRef { config: c, trial }))
            .collect()
    }

    /// The seed of a trial.
    pub fn trial_seed(&self, t: TrialRef) -> u64 {
        trial_seed(self.configurations[t.config].seed, t.trial)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pada_core::policy::PolicyKind;

    #[test]
    fn a_configuration_comes_back_as_the_same_run_config() {
        for policy in [
            PolicyKind::Sarsa,
            PolicyKind::LowPass { alpha: 0.834 },
            PolicyKind::MarkovLowPass { alpha: 0.1 },
            PolicyKind::Integrator { delta: 0.05 },
            PolicyKind::MarkovIntegrator { delta: 0.3 },
            PolicyKind::Pada { delta: 1.0 / 6.0 },
        ] {
            let cfg = RunConfig {
                policy,
                switch_at_s: Some(7333.0),
                mtbf_budget_s: None,
                seconds: 14_666.0,
                trials: 15,
                seed: u64::MAX,
            };
            let c = Configuration::new(3, TaskName::Leo, &cfg);
            let text = serde_json::to_string(&c).unwrap();
            let back: Configuration = serde_json::from_str(&text).unwrap();
            assert_eq!(back, c);
            assert_eq!(back.run_config().unwrap(), cfg);
            assert_eq!(back.task_name().unwrap(), TaskName::Leo);
        }
    }

    #[test]
    fn trials_are_numbered_configuration_by_configuration() {
        let cfg = |trials| RunConfig {
            policy: PolicyKind::Sarsa,
            switch_at_s: None,
            mtbf_budget_s: None,
            seconds: 60.0,
            trials,
            seed: 1,
        };
        let e = Experiment::new(
            ExperimentKind::Run,
            "x".into(),
            &[
                (TaskName::Pendulum, cfg(2)),
                (TaskName::PhysicalPendulum, cfg(3)),
            ],
        );
        let t = e.trials();
        assert_eq!(t.len(), 5);
        assert_eq!(
            t[1],
            TrialRef {
                config: 0,
                trial: 1
            }
        );
        assert_eq!(
            t[2],
            TrialRef {
                config: 1,
                trial: 0
            }
        );
        assert_eq!(e.trial_seed(t[4]), trial_seed(1, 2));
    }

    #[test]
    fn a_board_or_a_stray_parameter_is_refused() {
        let cfg = RunConfig {
            policy: PolicyKind::Sarsa,
            switch_at_s: None,
            mtbf_budget_s: None,
            seconds: 60.0,
            trials: 1,
            seed: 1,
        };
        let mut c = Configuration::new(0, TaskName::Pendulum, &cfg);
        c.parameter = Some(0.5);
        assert!(c
            .run_config()
            .unwrap_err()
            .to_string()
            .contains("takes no parameter"));
        c.parameter = None;
        c.board = Some("f405".into());
        assert!(c.run_config().unwrap_err().to_string().contains("board"));
        c.board = None;
        c.task = "cartpole".into();
        assert!(c
            .task_name()
            .unwrap_err()
            .to_string()
            .contains("valid: pendulum"));
    }
}
