//! A plan: an [`Experiment`] enumerated into independent trials, each with
//! its configuration, seed, learning time and expected output, and the
//! SHA-256 hash of all of it (with the pada version), which every trial
//! file and every result carries.

use super::experiment::{Configuration, Experiment, ExperimentKind};
use anyhow::{bail, Context};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

/// Version of the plan files' layout.
pub const PLAN_FORMAT: u32 = 1;

/// The pada version that writes and runs plans; part of the hash, since
/// another version may run a trial differently.
pub const PADA_VERSION: &str = env!("CARGO_PKG_VERSION");

/// One trial of a plan: everything `pada trial` needs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialSpec {
    /// Index in the plan (the array task index).
    pub index: u32,
    /// Its configuration.
    pub configuration: Configuration,
    /// Trial index within the configuration.
    pub trial: u32,
    /// The trial's seed, derived from the configuration's master seed
    /// (stated for readers; the runner derives it again and checks).
    pub trial_seed: u64,
    /// The file the trial writes, relative to the plan's directory.
    pub result: String,
}

impl TrialSpec {
    /// `12 (pendulum pada Δ=0.5, trial 3)`, for listings.
    pub fn describe(&self) -> String {
        format!(
            "{} ({}, trial {})",
            self.index, self.configuration.label, self.trial
        )
    }
}

/// The hashed content of a plan.
#[derive(Serialize)]
struct Hashed<'a> {
    format: u32,
    pada_version: &'a str,
    kind: ExperimentKind,
    command: &'a str,
    configurations: &'a [Configuration],
    trials: &'a [TrialSpec],
}

/// An experiment as a plan of trials.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The experiment.
    pub experiment: Experiment,
    /// Its trials, in index order.
    pub trials: Vec<TrialSpec>,
    /// SHA-256 of the plan, hex.
    pub hash: String,
}

/// The path of trial `index`'s result, relative to the plan's directory.
pub fn result_name(index: u32) -> String {
    format!("results/{index:06}.json")
}

/// The hex SHA-256 of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

impl Plan {
    /// Enumerates `experiment`'s trials and hashes them. Fails only if a
    /// number would not come back from the plan's JSON bit for bit.
    pub fn new(experiment: Experiment) -> anyhow::Result<Plan> {
        let trials: Vec<TrialSpec> = experiment
            .trials()
            .into_iter()
            .enumerate()
            .map(|(i, t)| TrialSpec {
                index: i as u32,
                configuration: experiment.configurations[t.config].clone(),
                trial: t.trial,
                trial_seed: experiment.trial_seed(t),
                result: result_name(i as u32),
            })
            .collect();
        for t in &trials {
            let text = serde_json::to_string(t)?;
            let back: TrialSpec = serde_json::from_str(&text)?;
            if back != *t {
                bail!(
                    "trial {} would not read back from its JSON as written ({text})",
                    t.describe()
                );
            }
        }
        let hash = hash_of(&experiment, &trials)?;
        Ok(Plan {
            experiment,
            trials,
            hash,
        })
    }

    /// Number of trials.
    pub fn len(&self) -> usize {
        self.trials.len()
    }

    /// Whether the plan has no trials.
    pub fn is_empty(&self) -> bool {
        self.trials.is_empty()
    }

    /// The first 12 hex digits of the hash, for names and messages.
    pub fn short_hash(&self) -> &str {
        &self.hash[..12]
    }
}

fn hash_of(experiment: &Experiment, trials: &[TrialSpec]) -> anyhow::Result<String> {
    let bytes = serde_json::to_vec(&Hashed {
        format: PLAN_FORMAT,
        pada_version: PADA_VERSION,
        kind: experiment.kind,
        command: &experiment.command,
        configurations: &experiment.configurations,
        trials,
    })
    .context("cannot encode the plan")?;
    Ok(sha256_hex(&bytes))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::tasks::TaskName;
    use crate::experiment::RunConfig;
    use pada_core::policy::PolicyKind;

    fn experiment(seed: u64) -> Experiment {
        Experiment::new(
            ExperimentKind::Run,
            "pada run".into(),
            &[(
                TaskName::Pendulum,
                RunConfig {
                    policy: PolicyKind::Pada { delta: 0.5 },
                    switch_at_s: None,
                    mtbf_budget_s: None,
                    seconds: 60.0,
                    trials: 3,
                    seed,
                },
            )],
        )
    }

    #[test]
    fn the_hash_depends_on_every_part() {
        let a = Plan::new(experiment(1)).unwrap();
        assert_eq!(a.hash.len(), 64);
        assert_eq!(a.hash, Plan::new(experiment(1)).unwrap().hash);
        assert_ne!(a.hash, Plan::new(experiment(2)).unwrap().hash);
        let mut e = a.experiment.clone();
        e.configurations[0].seconds = 61.0;
        assert_ne!(Plan::new(e).unwrap().hash, a.hash);
        let mut e = a.experiment.clone();
        e.command += " --seed 1";
        assert_ne!(Plan::new(e).unwrap().hash, a.hash);
        assert_eq!(a.trials[2].result, "results/000002.json");
        assert_eq!(a.trials[1].describe(), "1 (pendulum pada Δ=0.5, trial 1)");
    }

    #[test]
    fn sha256_of_a_known_string() {
        // FIPS 180-2, appendix B.1.
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }
}
