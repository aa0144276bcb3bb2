//! The learner's flags that `pada drive` and `pada sil` share, α, Δ and a
//! wear budget (`pada run` has these and the other algorithms' θ, σ and
//! weight), and the one check that turns flags into a policy for all three.

use crate::error::{usage, CliError};
use crate::experiment::algo::{check_mtbf_budget, policy_kind_of, Algo, PolicyFlags};
use clap::Args;
use pada_core::policy::PolicyKind;

/// α, Δ and a wear budget for the board's learner.
#[derive(Args, Debug, Clone)]
pub struct PolicyArgs {
    /// Low-pass α of Eq. 8 (lowpass, markov-lowpass; default 0.834).
    #[arg(long)]
    pub alpha: Option<f32>,
    /// Δ relative to the action range (integrator, markov-integrator, pada;
    /// default 0.5).
    #[arg(long)]
    pub delta: Option<f32>,
    /// Learn on a wear budget: the wear governor moves PADA's Δ or the
    /// low-pass filter's α to keep the predicted MTBF over the last 1200
    /// learning actions at or above SECONDS (pada or lowpass; not with
    /// --delta or --alpha).
    #[arg(long, value_name = "SECONDS")]
    pub mtbf_budget: Option<f32>,
}

impl PolicyArgs {
    /// The policy of `algo` with these flags, checked.
    pub fn policy(&self, algo: Algo) -> Result<PolicyKind, CliError> {
        checked_policy(algo, &PolicyFlags { alpha: self.alpha, delta: self.delta, ..PolicyFlags::default() }, self.mtbf_budget)
    }
}

/// The policy of `algo` with `flags` and a wear `budget` \[s\], checked:
/// a budget only with an algorithm the governor moves and without the
/// parameter it moves, and each flag only with an algorithm that takes it.
/// An error is one line naming the flag (exit code 2).
pub fn checked_policy(algo: Algo, flags: &PolicyFlags, budget: Option<f32>) -> Result<PolicyKind, CliError> {
    if let Some(b) = budget {
        check_mtbf_budget(algo, flags.alpha.is_some(), flags.delta.is_some(), b).map_err(usage)?;
    }
    policy_kind_of(algo, flags).map_err(|e| usage(e.0))
}
