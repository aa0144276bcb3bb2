//! What a run is: one algorithm with its parameter, for a number of
//! trials ([`RunConfig`]). A leaf: the runner and a trial both read it.

use pada_core::policy::PolicyKind;

/// What to run: one algorithm with its parameter, for a number of trials.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunConfig {
    /// The algorithm and its α or Δ.
    pub policy: PolicyKind,
    /// Learning time after which PADA or the low-pass filter switches back
    /// to SARSA(λ) (Section VIII) \[s\], if any.
    pub switch_at_s: Option<f64>,
    /// The wear governor's budget \[s\]: the predicted MTBF over the last
    /// 1200 learning actions it holds by moving PADA's Δ or the low-pass
    /// filter's α ([`pada_core::governor`]); `None` for a fixed Δ or α.
    pub mtbf_budget_s: Option<f32>,
    /// Learning time per trial \[s of simulated time\].
    pub seconds: f64,
    /// Number of trials.
    pub trials: u32,
    /// Master seed; trial seeds derive from it ([`crate::seed`]).
    pub seed: u64,
}

impl RunConfig {
    /// Environment steps one trial takes, learning and test runs (an
    /// estimate for progress bars: exact when no episode ends early).
    pub fn expected_steps(&self, period_s: f64, episode_steps: u32, test_interval: u32) -> u64 {
        let learning = (self.seconds / period_s).round() as u64;
        let episodes = learning.div_ceil(episode_steps.max(1) as u64);
        let tests = 1 + episodes.div_ceil(test_interval.max(1) as u64);
        (episodes + tests) * episode_steps as u64
    }
}
