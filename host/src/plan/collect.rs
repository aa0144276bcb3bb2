//! Gathering a plan's results for a merge: every trial's result must be
//! present and verify; otherwise the missing and corrupt ones are listed by
//! index and configuration, and nothing is reported.

use super::result::{self, ResultState, StoredResult, TrialTiming};
use super::spec::Plan;
use crate::experiment::TrialResult;
use std::fmt;
use std::path::Path;

/// A trial without a usable result.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    /// Its plan index.
    pub index: u32,
    /// `12 (pendulum pada Δ=0.5, trial 3)`.
    pub trial: String,
    /// `missing`, or why the file is not its intact result.
    pub what: String,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "trial {}: {}", self.trial, self.what)
    }
}

/// Every trial's state, in plan order.
pub struct Scan {
    /// The verified results (None where there is a problem).
    pub results: Vec<Option<StoredResult>>,
    /// The trials without a verified result.
    pub problems: Vec<Problem>,
}

impl Scan {
    /// Number of trials with a verified result.
    pub fn verified(&self) -> usize {
        self.results.iter().filter(|r| r.is_some()).count()
    }
}

/// Reads and verifies every result of `plan` in `dir`.
pub fn scan(dir: &Path, plan: &Plan) -> Scan {
    let mut results = Vec::with_capacity(plan.len());
    let mut problems = Vec::new();
    for spec in &plan.trials {
        let problem = |what: String| Problem {
            index: spec.index,
            trial: spec.describe(),
            what,
        };
        match result::read(dir, plan, spec.index) {
            ResultState::Verified(r) => results.push(Some(*r)),
            ResultState::Missing => {
                results.push(None);
                problems.push(problem("missing".into()));
            }
            ResultState::Corrupt(why) => {
                results.push(None);
                problems.push(problem(format!("corrupt: {why}")));
            }
        }
    }
    Scan { results, problems }
}

/// The results of a complete plan.
#[derive(Debug, Clone)]
pub struct Collected {
    /// Per configuration, in trial order.
    pub per_config: Vec<Vec<TrialResult>>,
    /// Every trial's timing, in plan order, with its configuration's index.
    pub timings: Vec<(usize, TrialTiming)>,
}

/// A plan with missing or corrupt results.
#[derive(Debug, Clone)]
pub struct Incomplete {
    /// Trials in the plan.
    pub total: usize,
    /// The trials without a verified result.
    pub problems: Vec<Problem>,
}

impl fmt::Display for Incomplete {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} of {} trials have no verified result: ",
            self.problems.len(),
            self.total
        )?;
        let shown: Vec<String> = self
            .problems
            .iter()
            .take(5)
            .map(|p| p.to_string())
            .collect();
        f.write_str(&shown.join("; "))?;
        if self.problems.len() > 5 {
            write!(f, "; and {} more", self.problems.len() - 5)?;
        }
        Ok(())
    }
}

impl std::error::Error for Incomplete {}

/// Every result of `plan` in `dir`, or the list of what is missing.
pub fn collect(dir: &Path, plan: &Plan) -> Result<Collected, Incomplete> {
    let scan = scan(dir, plan);
    if !scan.problems.is_empty() {
        return Err(Incomplete {
            total: plan.len(),
            problems: scan.problems,
        });
    }
    Ok(from_results(
        plan,
        scan.results.into_iter().flatten().collect(),
    ))
}

/// Groups verified results (one per trial, in plan order) by configuration.
pub fn from_results(plan: &Plan, results: Vec<StoredResult>) -> Collected {
    let mut per_config: Vec<Vec<TrialResult>> = plan
        .experiment
        .configurations
        .iter()
        .map(|c| Vec::with_capacity(c.trials as usize))
        .collect();
    let mut timings = Vec::with_capacity(results.len());
    for (spec, r) in plan.trials.iter().zip(results) {
        let c = spec.configuration.index as usize;
        per_config[c].push(r.result);
        timings.push((c, r.timing));
    }
    Collected {
        per_config,
        timings,
    }
}
