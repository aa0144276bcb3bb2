//! The wear governor in a host trial (`pada run --mtbf-budget`): set up
//! from the task, fed every learning action's damage per gearbox, and what
//! a trial reports about it.
//!
//! The rule itself is the learning core's ([`pada_core::governor`]), the
//! same on the chip; here it sees the paper's torques (the commanded
//! action, [`crate::experiment::task::Plant::commanded_torques`]), the
//! input of the trial's `mtbf_s`, so the budget it holds is the one the
//! trial measures.

use crate::experiment::task::TaskSpec;
use anyhow::anyhow;
use pada_core::episodes::wear;
use pada_core::fatigue::FatigueCounter;
use pada_core::governor::{Governor, GovernorConfig, GOVERNED_JOINTS};
use pada_core::policy::PolicyKind;
use serde::{Deserialize, Serialize};

/// What one trial's governor did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GovernorTrial {
    /// The budget \[s\].
    pub budget_s: f32,
    /// Whether the trial's MTBF over its first 1200 learning actions (the
    /// paper's, `mtbf_s`) is at least the budget.
    pub held: bool,
    /// The same for the physical MTBF (`physical_mtbf_s`), which the
    /// governor does not see.
    pub physical_held: bool,
    /// The Δ or α in force at the end.
    pub final_parameter: f32,
    /// The mean Δ or α over the learning actions.
    pub mean_parameter: f64,
    /// The share of learning actions taken at the floor (Δ of one level,
    /// α = 0.1).
    pub floor_fraction: f64,
    /// Moves of the governor.
    pub moves: u32,
    /// Learning actions after which the window's MTBF was below the budget.
    pub over_budget_steps: u64,
}

/// What a governor did over a trial's learning actions, counted as they
/// happen (by the host trial and by `pada run --board`).
#[derive(Debug, Clone, Default)]
pub struct GovernorStats {
    /// Sum of the parameter in force over the learning actions.
    parameter_sum: f64,
    floor_steps: u64,
    steps: u64,
}

impl GovernorStats {
    /// One learning action taken with `governor`'s Δ or α in force.
    pub fn record(&mut self, governor: &Governor) {
        self.parameter_sum += governor.parameter() as f64;
        self.floor_steps += (governor.rung() == 0) as u64;
        self.steps += 1;
    }

    /// The trial's record, given its two MTBFs.
    pub fn finish(&self, governor: &Governor, mtbf_s: f64, physical_mtbf_s: f64) -> GovernorTrial {
        let status = governor.status();
        let budget = governor.budget_s() as f64;
        let n = self.steps.max(1) as f64;
        GovernorTrial {
            budget_s: governor.budget_s(),
            held: mtbf_s >= budget,
            physical_held: physical_mtbf_s >= budget,
            final_parameter: status.parameter,
            mean_parameter: self.parameter_sum / n,
            floor_fraction: self.floor_steps as f64 / n,
            moves: status.moves,
            over_budget_steps: governor.state().over_budget_steps,
        }
    }
}

/// A trial's governor and its running statistics.
pub struct TrialGovernor {
    governor: Governor,
    gearboxes: usize,
    stats: GovernorStats,
}

impl TrialGovernor {
    /// A governor of `policy` on `spec`'s motor with `budget_s`; the
    /// caller sets the policy to [`parameter`](Self::parameter) before the
    /// first action.
    pub fn new(spec: &TaskSpec, policy: &PolicyKind, budget_s: f32) -> anyhow::Result<TrialGovernor> {
        let gearboxes = spec.gearboxes.min(GOVERNED_JOINTS);
        let config = GovernorConfig {
            budget_s,
            period_s: spec.control_period_s,
            gearbox: spec.weakest_gearbox(),
            worst_torque_nm: spec.worst_torque_nm,
            joints: gearboxes as u8,
        };
        let governor = Governor::new(policy, &spec.motor, &config).map_err(|e| anyhow!("--mtbf-budget: {e}"))?;
        Ok(TrialGovernor { governor, gearboxes, stats: GovernorStats::default() })
    }

    /// The Δ or α in force.
    pub fn parameter(&self) -> f32 {
        self.governor.parameter()
    }

    /// The governor.
    pub fn governor(&self) -> &Governor {
        &self.governor
    }

    /// One learning action: `before` is each gearbox's damage (Q16.48)
    /// before `fatigue` counted it. Returns the new Δ or α if the governor
    /// moved.
    pub fn observe<const N: usize>(&mut self, before: &[u64; N], fatigue: &FatigueCounter<N>) -> Option<f32> {
        self.stats.record(&self.governor);
        self.governor.observe(&wear::increments(before, fatigue, 0..self.gearboxes))
    }

    /// The trial's record, given its two MTBFs.
    pub fn finish(&self, mtbf_s: f64, physical_mtbf_s: f64) -> GovernorTrial {
        self.stats.finish(&self.governor, mtbf_s, physical_mtbf_s)
    }
}

