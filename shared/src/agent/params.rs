//! The learning parameters of SARSA(λ) (Section III) and how the weights
//! start, each checked for its range.

use crate::error::{check_range, ConfigError};
use crate::trace::TraceKind;

/// How weights start.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WeightInit {
    /// Every weight equal (optimistic initialisation when above the
    /// achievable returns).
    Constant(f32),
    /// Independent uniform draws in `[min, max]` (GRL uses U[0, 1]).
    Uniform {
        /// Lower end.
        min: f32,
        /// Upper end.
        max: f32,
    },
}

/// Learning parameters. [`Default`] is the paper's (Section VII): α 0.2,
/// γ 0.99, ε 0.05, λ 0.92, replacing traces pruned at 0.01, weights 0.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SarsaParams {
    /// Learning rate α, `0 < α ≤ 1`: Q moves by α·δ.
    pub alpha: f32,
    /// Discount γ per step, `0 ≤ γ ≤ 1`.
    pub gamma: f32,
    /// Trace decay λ per step, `0 ≤ λ ≤ 1`.
    pub lambda: f32,
    /// Exploration rate ε, `0 ≤ ε ≤ 1`.
    pub epsilon: f32,
    /// Trace entries with eligibility `(γλ)^k` below this are pruned,
    /// `0 < threshold < 1`.
    pub trace_threshold: f32,
    /// Replacing (default) or accumulating traces.
    pub trace_kind: TraceKind,
    /// Initial weights.
    pub init: WeightInit,
}

impl Default for SarsaParams {
    /// [`SarsaParams::SECTION_VII`].
    fn default() -> Self {
        SarsaParams::SECTION_VII
    }
}

impl SarsaParams {
    /// The paper's parameters (Section VII: α 0.2, γ 0.99, ε 0.05, λ 0.92),
    /// replacing traces pruned at 0.01, from zero weights.
    pub const SECTION_VII: SarsaParams = SarsaParams {
        alpha: 0.2,
        gamma: 0.99,
        lambda: 0.92,
        epsilon: 0.05,
        trace_threshold: 0.01,
        trace_kind: TraceKind::Replacing,
        init: WeightInit::Constant(0.0),
    };

    /// Checks every parameter's range.
    pub fn validate(&self) -> Result<(), ConfigError> {
        if !(self.alpha.is_finite() && self.alpha > 0.0 && self.alpha <= 1.0) {
            return Err(ConfigError::new("alpha", self.alpha, "0 < alpha <= 1"));
        }
        check_range("gamma", self.gamma, 0.0, 1.0, "0 <= gamma <= 1")?;
        check_range("lambda", self.lambda, 0.0, 1.0, "0 <= lambda <= 1")?;
        check_range("epsilon", self.epsilon, 0.0, 1.0, "0 <= epsilon <= 1")?;
        if !(self.trace_threshold.is_finite() && self.trace_threshold > 0.0 && self.trace_threshold < 1.0) {
            return Err(ConfigError::new("trace_threshold", self.trace_threshold, "0 < trace_threshold < 1"));
        }
        match self.init {
            WeightInit::Constant(c) => check_range("init", c, -30000.0, 30000.0, "-30000 <= init <= 30000"),
            WeightInit::Uniform { min, max } => {
                check_range("init.min", min, -30000.0, 30000.0, "-30000 <= init.min <= init.max <= 30000")?;
                check_range("init.max", max, min, 30000.0, "-30000 <= init.min <= init.max <= 30000")
            }
        }
    }
}
